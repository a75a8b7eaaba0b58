// The allocator interface, what both allocators share, and the device's
// allocator registry.
#include "vkrc/memory.hpp"

#include "memory_internal.hpp"
#include "recent_answers.hpp"

#include <algorithm>
#include <limits>
#include <string>

VKRC_BEGIN_NAMESPACE

bool DeviceView::extension_enabled(const char* name) const noexcept {
    return detail::contains(s_->enabled_extensions, name);
}

HeapStatistics AllocatorStatistics::total() const noexcept {
    HeapStatistics t;
    for (std::uint32_t i = 0; i < heap_count; ++i) {
        detail::add_tallies(t, heaps[i]);
        t.budget += heaps[i].budget;
        t.usage += heaps[i].usage;
    }
    return t;
}

AllocatorStatistics DeviceAllocator::statistics(DeviceView device) const {
    AllocatorStatistics stats;
    fill_budget(device, stats);
    return stats;
}

void fill_budget(DeviceView device, AllocatorStatistics& stats) noexcept {
    const auto& props = device.memory_properties();
    stats.heap_count = props.memoryHeapCount;
    if (device.extension_enabled(VK_EXT_MEMORY_BUDGET_EXTENSION_NAME)) {
        VkPhysicalDeviceMemoryBudgetPropertiesEXT budget{
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_BUDGET_PROPERTIES_EXT};
        VkPhysicalDeviceMemoryProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_PROPERTIES_2, &budget};
        const auto& physical = device.physical_device();
        physical.fn().vkGetPhysicalDeviceMemoryProperties2(physical.vk(), &props2);
        for (std::uint32_t i = 0; i < props.memoryHeapCount; ++i) {
            stats.heaps[i].budget = budget.heapBudget[i];
            stats.heaps[i].usage = budget.heapUsage[i];
        }
        return;
    }
    for (std::uint32_t i = 0; i < props.memoryHeapCount; ++i) {
        stats.heaps[i].budget = props.memoryHeaps[i].size;
        stats.heaps[i].usage = stats.heaps[i].block_bytes;
    }
}

namespace detail {

namespace {
// choose_memory_type for request, remembered: its answer depends only on
// the device's memory properties and these inputs, and a program allocates
// many resources of few kinds. One answer per thread (no lock), keyed by the
// device's process-unique id (RecentAnswers); a refusal is not kept.
std::uint32_t memory_type_for(const Caller& caller, DeviceView device, const AllocationRequest& request) {
    struct Question {
        std::uint64_t device_id = 0;  // 0: empty
        std::uint32_t type_bits = 0;
        MemoryUsage usage{};
        VkMemoryPropertyFlags required = 0;
        VkMemoryPropertyFlags preferred = 0;
        bool operator==(const Question&) const = default;
    };
    thread_local RecentAnswers<Question, std::uint32_t, 1> types;
    const MemoryIntent& intent = request.intent;
    const Question q{device.state().id, request.requirements.memoryTypeBits, intent.usage, intent.required_flags,
                     intent.preferred_flags};
    if (const std::uint32_t* type = types.find(q)) return *type;
    const std::uint32_t type = choose_memory_type(device.memory_properties(), q.type_bits, intent, caller.name());
    types.keep(q, type);
    return type;
}
}  // namespace

std::uint32_t checked_memory_type(const Caller& caller, DeviceView device, const AllocationRequest& request) {
    const auto& props = device.memory_properties();
    const std::uint32_t type = memory_type_for(caller, device, request);
    caller.require(request.requirements.size != 0, "size is 0");
    caller.require(request.dedicated_buffer == VK_NULL_HANDLE || request.dedicated_image == VK_NULL_HANDLE,
                   "both dedicated_buffer and dedicated_image are set");
    const std::uint32_t heap = props.memoryTypes[type].heapIndex;
    caller.require(request.requirements.size <= props.memoryHeaps[heap].size, request.requirements.size,
                   " bytes requested, more than the whole of memory heap ", heap, " (", props.memoryHeaps[heap].size,
                   " bytes)");
    return type;
}

VkDeviceMemory allocate_device_memory(DeviceView device, VkDeviceSize size, std::uint32_t type,
                                      VkBuffer dedicated_buffer, VkImage dedicated_image, bool device_address,
                                      std::byte** mapped) {
    VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    info.allocationSize = size;
    info.memoryTypeIndex = type;
    VkMemoryDedicatedAllocateInfo dedicated{VK_STRUCTURE_TYPE_MEMORY_DEDICATED_ALLOCATE_INFO};
    if (dedicated_buffer != VK_NULL_HANDLE || dedicated_image != VK_NULL_HANDLE) {
        dedicated.buffer = dedicated_buffer;
        dedicated.image = dedicated_image;
        info.pNext = &dedicated;
    }
    VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO, info.pNext};
    if (device_address) {
        flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
        info.pNext = &flags;
    }
    VkDeviceMemory memory = VK_NULL_HANDLE;
    check(device.fn().vkAllocateMemory(device.vk(), &info, nullptr, &memory), "vkAllocateMemory");
    *mapped = nullptr;
    if (device.memory_properties().memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) {
        void* p = nullptr;
        VkResult r = device.fn().vkMapMemory(device.vk(), memory, 0, VK_WHOLE_SIZE, 0, &p);
        if (r < 0) {
            device.fn().vkFreeMemory(device.vk(), memory, nullptr);
            check(r, "vkMapMemory");
        }
        *mapped = static_cast<std::byte*>(p);
    }
    return memory;
}

// ---------------------------------------------------------------- the device's allocators

AllocatorRegistry::AllocatorRegistry() = default;
AllocatorRegistry::~AllocatorRegistry() = default;

DeviceAllocator& AllocatorRegistry::default_allocator() {
    if (DeviceAllocator* made = default_.load(__ATOMIC_ACQUIRE)) return *made;
    LockGuard lock(mutex_);
    if (DeviceAllocator* made = default_.load(__ATOMIC_RELAXED)) return *made;
    auto pool = make_allocator<PoolAllocator>();
    allocators_.push_back(pool);
    std::rotate(allocators_.begin(), allocators_.end() - 1, allocators_.end());  // the default one first
    default_.store(pool.get(), __ATOMIC_RELEASE);
    return *pool;
}

bool AllocatorRegistry::kept_recently(const DeviceAllocator* allocator) const noexcept {
    const std::size_t n = recent_count_.load(__ATOMIC_ACQUIRE);
    for (std::size_t i = 0; i < n; ++i) {
        if (recent_[i].load(__ATOMIC_RELAXED) == allocator) return true;
    }
    return false;
}

void AllocatorRegistry::keep(DeviceAllocator* allocator) {
    if (kept_recently(allocator)) return;
    LockGuard lock(mutex_);
    auto same = [&](const Ref<DeviceAllocator>& a) { return a.get() == allocator; };
    if (std::find_if(allocators_.begin(), allocators_.end(), same) == allocators_.end()) {
        allocators_.push_back(Ref<DeviceAllocator>::share(allocator));
    }
    const std::size_t n = recent_count_.load(__ATOMIC_RELAXED);
    if (n < recent_slots && !kept_recently(allocator)) {
        recent_[n].store(allocator, __ATOMIC_RELAXED);
        recent_count_.store(n + 1, __ATOMIC_RELEASE);
    }
}

void AllocatorRegistry::release_all(DeviceState& device) noexcept {
    for (auto& a : allocators_) a->release(DeviceView(device));
    allocators_.clear();
    recent_count_.store(0, __ATOMIC_RELAXED);
    default_.store(nullptr, __ATOMIC_RELAXED);
}

}  // namespace detail

VKRC_END_NAMESPACE
