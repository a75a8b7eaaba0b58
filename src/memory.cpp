#include "vkrc/memory.hpp"

#include "memory_internal.hpp"

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
        t.block_bytes += heaps[i].block_bytes;
        t.allocation_bytes += heaps[i].allocation_bytes;
        t.block_count += heaps[i].block_count;
        t.allocation_count += heaps[i].allocation_count;
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

// ---------------------------------------------------------------- memory types

bool intent_needs_mapping(const MemoryIntent& intent) noexcept {
    return intent.usage == MemoryUsage::upload || intent.usage == MemoryUsage::readback ||
           (intent.required_flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT);
}

namespace {
// A few bits at most: cheaper than the library call std::popcount becomes
// without -mpopcnt.
int flag_count(VkMemoryPropertyFlags flags) noexcept {
    int n = 0;
    for (; flags; flags &= flags - 1) ++n;
    return n;
}
}  // namespace

namespace {
struct FlagChoice {
    VkMemoryPropertyFlags required, preferred, avoided;
};
// The intent's own flags plus what its usage implies.
FlagChoice flags_of(const MemoryIntent& intent) noexcept {
    VkMemoryPropertyFlags required = intent.required_flags;
    VkMemoryPropertyFlags preferred = intent.preferred_flags;
    VkMemoryPropertyFlags avoided = 0;
    switch (intent.usage) {
        case MemoryUsage::gpu_only:
            preferred |= VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
            avoided |= VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
            break;
        case MemoryUsage::upload:
            required |= VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
            preferred |= VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
            break;
        case MemoryUsage::readback:
            required |= VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
            preferred |= VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
            break;
        case MemoryUsage::custom: break;
    }
    return {required, preferred, avoided};
}
}  // namespace

int find_memory_type(const VkPhysicalDeviceMemoryProperties& properties, std::uint32_t type_bits,
                     const MemoryIntent& intent) noexcept {
    const auto [required, preferred, avoided] = flags_of(intent);
    // Memory only special resources may use is never chosen unless required.
    const VkMemoryPropertyFlags special = VK_MEMORY_PROPERTY_PROTECTED_BIT | VK_MEMORY_PROPERTY_LAZILY_ALLOCATED_BIT |
                                          VK_MEMORY_PROPERTY_DEVICE_COHERENT_BIT_AMD;
    int best = -1;
    int best_score = 0;
    for (std::uint32_t i = 0; i < properties.memoryTypeCount; ++i) {
        if (!(type_bits & (1u << i))) continue;
        const VkMemoryPropertyFlags flags = properties.memoryTypes[i].propertyFlags;
        if ((flags & required) != required) continue;
        if (flags & special & ~required) continue;
        const int score = flag_count(flags & preferred) - flag_count(flags & avoided);
        if (best < 0 || score > best_score) {
            best = static_cast<int>(i);
            best_score = score;
        }
    }
    return best;
}

std::uint32_t choose_memory_type(const VkPhysicalDeviceMemoryProperties& properties, std::uint32_t type_bits,
                                 const MemoryIntent& intent, const char* who) {
    int type = find_memory_type(properties, type_bits, intent);
    if (type < 0) {
        throw UsageError(std::string(who) + ": no memory type of the device has the required property flags 0x" +
                         detail::hex(flags_of(intent).required) + " among the resource's allowed types 0x" +
                         detail::hex(type_bits));
    }
    return static_cast<std::uint32_t>(type);
}

namespace detail {

std::string bytes_text(VkDeviceSize n) { return std::to_string(n) + " bytes"; }

void check_request(DeviceView device, const AllocationRequest& request, std::uint32_t type, const char* who) {
    if (request.requirements.size == 0) throw UsageError(std::string(who) + ": size is 0");
    if (request.dedicated_buffer != VK_NULL_HANDLE && request.dedicated_image != VK_NULL_HANDLE) {
        throw UsageError(std::string(who) + ": both dedicated_buffer and dedicated_image are set");
    }
    const auto& props = device.memory_properties();
    const std::uint32_t heap = props.memoryTypes[type].heapIndex;
    if (request.requirements.size > props.memoryHeaps[heap].size) {
        throw UsageError(std::string(who) + ": " + bytes_text(request.requirements.size) +
                         " requested, more than the whole of memory heap " + std::to_string(heap) + " (" +
                         bytes_text(props.memoryHeaps[heap].size) + ")");
    }
}

VkDeviceMemory allocate_device_memory(DeviceView device, VkDeviceSize size, std::uint32_t type,
                                      VkBuffer dedicated_buffer, VkImage dedicated_image, std::byte** mapped) {
    VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    info.allocationSize = size;
    info.memoryTypeIndex = type;
    VkMemoryDedicatedAllocateInfo dedicated{VK_STRUCTURE_TYPE_MEMORY_DEDICATED_ALLOCATE_INFO};
    if (dedicated_buffer != VK_NULL_HANDLE || dedicated_image != VK_NULL_HANDLE) {
        dedicated.buffer = dedicated_buffer;
        dedicated.image = dedicated_image;
        info.pNext = &dedicated;
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

namespace {
// vkFlushMappedMemoryRanges or vkInvalidateMappedMemoryRanges (one signature)
// over the atom-aligned range that covers the bytes, within the allocation.
void sync_mapped_range(const AllocationState& s, PFN_vkFlushMappedMemoryRanges DeviceFunctions::*call, const char* name,
                       VkDeviceSize offset, VkDeviceSize size) {
    if (s.coherent) return;
    const MemoryRange r = mapped_range(s.info.offset, s.info.size, s.info.memory_size, s.atom, offset, size);
    if (r.size == 0) return;
    VkMappedMemoryRange range{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE, nullptr, s.info.memory, r.offset, r.size};
    check((s.device->fn.*call)(s.device->device, 1, &range), name);
}
}  // namespace

void AllocationState::flush(VkDeviceSize offset, VkDeviceSize size) const {
    sync_mapped_range(*this, &DeviceFunctions::vkFlushMappedMemoryRanges, "vkFlushMappedMemoryRanges", offset, size);
}

void AllocationState::invalidate(VkDeviceSize offset, VkDeviceSize size) const {
    sync_mapped_range(*this, &DeviceFunctions::vkInvalidateMappedMemoryRanges, "vkInvalidateMappedMemoryRanges", offset,
                      size);
}

void AllocationState::on_last_release() noexcept {
    // The C++ state outlives its last handle until the GPU is done; only the
    // device reference goes now (a queued action holds no references).
    Ref<DeviceState> d = std::move(device);
    d->destroy_after_gpu({[](DeviceState& dev, std::uint64_t, void* context) noexcept {
                              auto* self = static_cast<AllocationState*>(context);
                              try {
                                  self->allocator->free(DeviceView(dev), self->info);
                              } catch (...) {
                                  // Only a range from another allocator throws, and
                                  // Allocation::create checked the range's origin.
                              }
                              delete self;
                          },
                          0, this});
}

[[noreturn]] void throw_not_host_visible(const char* who) {
    throw UsageError(std::string(who) +
                     ": the memory is not host-visible (allocate with MemoryUsage::upload or readback, or require "
                     "VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)");
}

[[noreturn]] void throw_out_of_range(const char* who, VkDeviceSize offset, std::size_t count, std::size_t element,
                                     VkDeviceSize size) {
    throw UsageError(std::string(who) + ": " + std::to_string(count) + " elements of " + std::to_string(element) +
                     " bytes at offset " + std::to_string(offset) + " do not fit in the " + std::to_string(size) +
                     "-byte allocation" +
                     (element != 0 && count > std::numeric_limits<VkDeviceSize>::max() / element
                          ? " (the byte count overflows)"
                          : ""));
}

}  // namespace detail

// ---------------------------------------------------------------- Allocation

Allocation Allocation::create(const Device& device, const AllocationRequest& request,
                              const SharedAllocator& allocator) {
    if (!device) throw UsageError("vkrc::Allocation::create: the Device handle is empty");
    auto& s = *device.state();
    DeviceAllocator* a = allocator.get();
    if (a) {
        s.allocators.keep(allocator);
    } else {
        a = &s.allocators.default_allocator();
    }
    AllocationInfo info = a->allocate(DeviceView(s), request);
    if (info.allocator != a) {
        throw UsageError("vkrc::Allocation::create: the allocator returned a range that names another allocator");
    }
    if (info.memory == VK_NULL_HANDLE) {
        // An allocator that reports no memory instead of throwing: the same as running out.
        throw Error(VK_ERROR_OUT_OF_DEVICE_MEMORY, "vkrc::DeviceAllocator::allocate");
    }
    detail::AllocationState* st = nullptr;
    try {
        st = new detail::AllocationState;
    } catch (...) {
        a->free(DeviceView(s), info);
        throw;
    }
    st->device = detail::Ref<detail::DeviceState>::share(&s);
    st->allocator = a;
    const VkMemoryPropertyFlags flags =
        device.physical_device().memory_properties().memoryTypes[info.memory_type].propertyFlags;
    st->coherent = (flags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT) || !(flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT);
    st->atom = std::max<VkDeviceSize>(1, device.physical_device().properties().limits.nonCoherentAtomSize);
    // GPU-only memory is not for the host even where the type is mappable,
    // so that code written on a unified-memory device works everywhere.
    if (!intent_needs_mapping(request.intent)) info.mapped = nullptr;
    st->info = info;
    return Allocation(detail::Ref<detail::AllocationState>(st));
}

namespace {
void check_flush_range(const detail::AllocationState& s, VkDeviceSize offset, VkDeviceSize size, const char* who) {
    if (!s.info.mapped) detail::throw_not_host_visible(who);
    if (size == VK_WHOLE_SIZE) {
        if (offset > s.info.size) detail::throw_out_of_range(who, offset, 0, 1, s.info.size);
    } else {
        detail::check_mapped_range(who, offset, size, 1, s.info.size);
    }
}
}  // namespace

void Allocation::flush(VkDeviceSize offset, VkDeviceSize size) const {
    check_flush_range(*state_, offset, size, "vkrc::Allocation::flush");
    state_->flush(offset, size);
}

void Allocation::invalidate(VkDeviceSize offset, VkDeviceSize size) const {
    check_flush_range(*state_, offset, size, "vkrc::Allocation::invalidate");
    state_->invalidate(offset, size);
}

DeviceAllocator& default_allocator(const Device& device) { return device.state()->allocators.default_allocator(); }

AllocatorStatistics memory_statistics(const Device& device) {
    return device.state()->allocators.default_allocator().statistics(DeviceView(*device.state()));
}

// ---------------------------------------------------------------- DedicatedAllocator

AllocationInfo DedicatedAllocator::allocate(DeviceView device, const AllocationRequest& request) {
    constexpr const char* who = "vkrc::DedicatedAllocator::allocate";
    const auto& props = device.memory_properties();
    const std::uint32_t type = choose_memory_type(props, request.requirements.memoryTypeBits, request.intent, who);
    detail::check_request(device, request, type, who);
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
            dedicated_info ? request.dedicated_image : VK_NULL_HANDLE, &info.mapped);
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
    auto& heap = stats_.heaps[props.memoryTypes[type].heapIndex];
    detail::add_block(heap, info.size);
    detail::add_range(heap, info.size);
    stats_.vk_allocate_calls += 1;
    return info;
}

void DedicatedAllocator::free(DeviceView device, const AllocationInfo& allocation) {
    if (allocation.allocator != this) {
        throw UsageError("vkrc::DedicatedAllocator::free: the allocation was made by another allocator");
    }
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

// ---------------------------------------------------------------- the device's allocators

namespace detail {

DeviceAllocator& AllocatorRegistry::default_allocator() {
    LockGuard lock(mutex_);
    if (!default_) {
        auto pool = make_allocator<PoolAllocator>();
        allocators_.push_back(pool);
        std::rotate(allocators_.begin(), allocators_.end() - 1, allocators_.end());  // the default one first
        default_ = pool.get();
    }
    return *default_;
}

void AllocatorRegistry::keep(const Ref<DeviceAllocator>& allocator) {
    LockGuard lock(mutex_);
    auto same = [&](const Ref<DeviceAllocator>& a) { return a.get() == allocator.get(); };
    if (std::find_if(allocators_.begin(), allocators_.end(), same) == allocators_.end()) {
        allocators_.push_back(allocator);
    }
}

void AllocatorRegistry::release_all(DeviceState& device) noexcept {
    for (auto& a : allocators_) a->release(DeviceView(device));
    allocators_.clear();
    default_ = nullptr;
}

}  // namespace detail

VKRC_END_NAMESPACE
