// DedicatedAllocator: one VkDeviceMemory per allocation.
#include "vkrc/memory.hpp"

#include "memory_internal.hpp"

VKRC_BEGIN_NAMESPACE

AllocationInfo DedicatedAllocator::allocate(DeviceView device, const AllocationRequest& request) {
    const detail::Caller caller{"vkrc::DedicatedAllocator::allocate"};
    const std::uint32_t type = detail::checked_memory_type(caller, device, request);
    const bool dedicated_info = request.requires_dedicated || request.prefers_dedicated || request.intent.dedicated;
    {
        // Reserved now, so that concurrent calls cannot pass the limit together.
        LockGuard lock(mutex_);
        if (memory_objects_ >= device.limits().maxMemoryAllocationCount) {
            throw Error(VK_ERROR_TOO_MANY_OBJECTS, "vkAllocateMemory");
        }
        ++memory_objects_;
    }
    AllocationInfo info;
    try {
        info.memory = detail::allocate_device_memory(
            device, request.requirements.size, type, dedicated_info ? request.dedicated_buffer : VK_NULL_HANDLE,
            dedicated_info ? request.dedicated_image : VK_NULL_HANDLE, request.device_address, &info.mapped);
    } catch (...) {
        LockGuard lock(mutex_);
        --memory_objects_;
        throw;
    }
    info.size = request.requirements.size;
    info.memory_size = request.requirements.size;
    info.memory_type = type;
    info.dedicated = true;
    info.allocator = this;
    LockGuard lock(mutex_);
    auto& heap = stats_.heaps[device.memory_properties().memoryTypes[type].heapIndex];
    detail::add_block(heap, info.size);
    detail::add_range(heap, info.size);
    stats_.vk_allocate_calls += 1;
    return info;
}

void DedicatedAllocator::free(DeviceView device, const AllocationInfo& allocation) {
    detail::Caller("vkrc::DedicatedAllocator::free")
        .require(allocation.allocator == this, "the allocation was made by another allocator");
    device.fn().vkFreeMemory(device.vk(), allocation.memory, nullptr);
    LockGuard lock(mutex_);
    auto& heap = stats_.heaps[device.memory_properties().memoryTypes[allocation.memory_type].heapIndex];
    detail::remove_block(heap, allocation.size);
    detail::remove_range(heap, allocation.size);
    memory_objects_ -= 1;
}

AllocatorStatistics DedicatedAllocator::statistics(DeviceView device) const {
    AllocatorStatistics stats;
    {
        LockGuard lock(mutex_);
        stats = stats_;
    }
    fill_budget(device, stats);
    return stats;
}
VKRC_END_NAMESPACE
