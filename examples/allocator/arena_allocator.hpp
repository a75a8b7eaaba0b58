// A user-written vkrc allocator: one bump arena (a single VkDeviceMemory) per
// memory type. Freed ranges are only counted; an arena rewinds when its last
// range is freed. Used by examples/allocator and by the tests.
#pragma once

#include <vkrc/memory.hpp>

#include <algorithm>
#include <map>
#include <mutex>

class ArenaAllocator final : public vkrc::DeviceAllocator {
public:
    explicit ArenaAllocator(VkDeviceSize arena_size) : arena_size_(arena_size) {}

    vkrc::AllocationInfo allocate(vkrc::DeviceView device, const vkrc::AllocationRequest& request) override {
        const auto& req = request.requirements;
        if (req.size == 0 || req.size > arena_size_)
            throw vkrc::UsageError("ArenaAllocator: size 0 or above the arena");
        // Its arenas are allocated without VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT:
        // refusing is how an allocator that cannot honour the request says so.
        if (request.device_address) throw vkrc::UsageError("ArenaAllocator: no device-address memory");
        auto type =
            vkrc::choose_memory_type(device.memory_properties(), req.memoryTypeBits, request.intent, "ArenaAllocator");
        std::lock_guard lock(mutex_);
        Arena& a = arenas_[type];
        if (a.memory == VK_NULL_HANDLE) {
            VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, nullptr, arena_size_, type};
            vkrc::check(device.fn().vkAllocateMemory(device.vk(), &info, nullptr, &a.memory), "vkAllocateMemory");
            if (device.memory_properties().memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) {
                void* p = nullptr;
                vkrc::check(device.fn().vkMapMemory(device.vk(), a.memory, 0, VK_WHOLE_SIZE, 0, &p), "vkMapMemory");
                a.mapped = static_cast<std::byte*>(p);
            }
        }
        // Non-coherent atoms too, so a flush never reaches a neighbour.
        VkDeviceSize align = std::max(req.alignment, device.limits().nonCoherentAtomSize);
        VkDeviceSize offset = (a.top + align - 1) / align * align;
        if (offset + req.size > arena_size_) throw vkrc::Error(VK_ERROR_OUT_OF_DEVICE_MEMORY, "ArenaAllocator");
        a.top = offset + req.size;
        a.live += 1;
        allocations += 1;
        return {a.memory, offset, req.size, arena_size_, type, a.mapped ? a.mapped + offset : nullptr,
                false,    this,   nullptr};
    }

    void free(vkrc::DeviceView, const vkrc::AllocationInfo& allocation) override {
        if (allocation.allocator != this) throw vkrc::UsageError("ArenaAllocator::free: not one of mine");
        std::lock_guard lock(mutex_);
        Arena& a = arenas_[allocation.memory_type];
        if (--a.live == 0) a.top = 0;
        frees += 1;
    }

    void release(vkrc::DeviceView device) noexcept override {
        std::lock_guard lock(mutex_);
        for (auto& [type, a] : arenas_) device.fn().vkFreeMemory(device.vk(), a.memory, nullptr);
        arenas_.clear();
        released = true;
    }

    std::uint64_t allocations = 0, frees = 0;  // read when no other thread allocates
    bool released = false;

private:
    struct Arena {
        VkDeviceMemory memory = VK_NULL_HANDLE;
        std::byte* mapped = nullptr;
        VkDeviceSize top = 0;
        std::uint32_t live = 0;
    };
    VkDeviceSize arena_size_;
    std::mutex mutex_;
    std::map<std::uint32_t, Arena> arenas_;
};
