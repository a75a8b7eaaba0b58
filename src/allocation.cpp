// Allocation: its state (flush, invalidate, deferred free) and the handle.
#include "vkrc/memory.hpp"

#include "memory_internal.hpp"
#include "object_state.hpp"

#include <algorithm>
#include <limits>
#include <string>

VKRC_BEGIN_NAMESPACE

namespace detail {

namespace {
// vkFlushMappedMemoryRanges or vkInvalidateMappedMemoryRanges (one signature)
// over the atom-aligned range that covers the bytes, within the allocation.
void sync_mapped_range(const AllocationState& s, PFN_vkFlushMappedMemoryRanges DeviceFunctions::*call, const char* name,
                       VkDeviceSize offset, VkDeviceSize size) {
    if (s.coherent) return;
    const MemoryRange r = mapped_range(s.info.offset, s.info.size, s.info.memory_size, s.atom, offset, size);
    if (r.size == 0) return;
    VkMappedMemoryRange range{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE, nullptr, s.info.memory, r.offset, r.size};
    check((s.device.state()->fn.*call)(s.device.state()->device, 1, &range), name);
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
    DeviceLink d = std::move(device);
    d.state()->destroy_after_gpu({[](DeviceState& dev, std::uint64_t, void* context) noexcept {
                                      auto* self = static_cast<AllocationState*>(context);
                                      try {
                                          self->allocator->free(DeviceView(dev), self->info);
                                      } catch (...) {
                                          // Only a range from another allocator throws, and
                                          // Allocation::create checked the range's origin.
                                      }
                                      delete self;
                                  },
                                  0, this},
                                 serial());
}

// The public header's inline checks hand over the caller's name as text.
[[noreturn]] void throw_not_host_visible(const char* who) {
    Caller(who).refuse(
        "the memory is not host-visible (allocate with MemoryUsage::upload or readback, or require "
        "VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)");
}

[[noreturn]] void throw_not_host_coherent(const char* who) {
    Caller(who).refuse(
        "the memory is not host-coherent (require VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, or use "
        "Allocation::write, which flushes)");
}

[[noreturn]] void throw_out_of_range(const char* who, VkDeviceSize offset, std::size_t count, std::size_t element,
                                     VkDeviceSize size) {
    const bool overflows = element != 0 && count > std::numeric_limits<VkDeviceSize>::max() / element;
    Caller(who).refuse(count, " elements of ", element, " bytes at offset ", offset, " do not fit in the ", size,
                       "-byte allocation", overflows ? " (the byte count overflows)" : "");
}

}  // namespace detail

Allocation Allocation::create(const Device& device, const AllocationRequest& request, AllocatorView allocator) {
    const detail::Caller caller{"vkrc::Allocation::create"};
    caller.require_handle(device, "the Device");
    auto& s = *device.state();
    DeviceAllocator* a = allocator.get();
    if (a) {
        s.keep_allocator(a);
    } else {
        a = &s.default_allocator();
    }
    AllocationInfo info = a->allocate(DeviceView(s), request);
    caller.require(info.allocator == a, "the allocator returned a range that names another allocator");
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
    st->device = device;
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

DeviceAllocator& default_allocator(const Device& device) { return device.state()->default_allocator(); }

AllocatorStatistics memory_statistics(const Device& device) {
    return device.state()->default_allocator().statistics(DeviceView(*device.state()));
}

VKRC_END_NAMESPACE
