// Helpers shared by the allocators (not installed).
#pragma once

#include "caller.hpp"
#include "text.hpp"
#include "vkrc/memory.hpp"

#include <string>

VKRC_BEGIN_NAMESPACE
namespace detail {

// The memory type an allocator gives request (choose_memory_type); throws
// UsageError for a zero size, two dedicated resources, or a size larger
// than the type's heap.
std::uint32_t checked_memory_type(const Caller& caller, DeviceView device, const AllocationRequest& request);
// vkAllocateMemory (with VkMemoryDedicatedAllocateInfo when a resource is
// given, VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT when device_address), mapped
// whole when host-visible.
VkDeviceMemory allocate_device_memory(DeviceView device, VkDeviceSize size, std::uint32_t type,
                                      VkBuffer dedicated_buffer, VkImage dedicated_image, bool device_address,
                                      std::byte** mapped);

// The statistics bookkeeping both allocators do: a VkDeviceMemory of bytes
// made or freed (a block, or a dedicated allocation), a range of bytes
// handed out or taken back (a dedicated allocation is both). A count and its
// bytes always move together.
inline void tally(VkDeviceSize& total, std::uint32_t& count, VkDeviceSize bytes, bool add) noexcept {
    total = add ? total + bytes : total - bytes;
    count = add ? count + 1 : count - 1;
}
inline void add_block(HeapStatistics& heap, VkDeviceSize bytes) noexcept {
    tally(heap.block_bytes, heap.block_count, bytes, true);
}
inline void remove_block(HeapStatistics& heap, VkDeviceSize bytes) noexcept {
    tally(heap.block_bytes, heap.block_count, bytes, false);
}
inline void add_range(HeapStatistics& heap, VkDeviceSize bytes) noexcept {
    tally(heap.allocation_bytes, heap.allocation_count, bytes, true);
}
inline void remove_range(HeapStatistics& heap, VkDeviceSize bytes) noexcept {
    tally(heap.allocation_bytes, heap.allocation_count, bytes, false);
}
// Adds from's block and range tallies to to's; budget and usage are left
// alone (fill_budget reads them from the device).
inline void add_tallies(HeapStatistics& to, const HeapStatistics& from) noexcept {
    to.block_bytes += from.block_bytes;
    to.allocation_bytes += from.allocation_bytes;
    to.block_count += from.block_count;
    to.allocation_count += from.allocation_count;
}

// A pool's new block grows it by at least 1 / pool_growth_divisor of what
// it holds: its last, part-used block stays a bounded share of it.
inline constexpr VkDeviceSize pool_growth_divisor = 8;
// The size of a pool's next block (see PoolAllocatorCreateInfo): for a
// request of request bytes (aligned and padded) in a pool that holds reserved
// bytes of a heap of heap_size bytes.
VkDeviceSize next_block_size(const PoolAllocatorCreateInfo& info, VkDeviceSize heap_size, VkDeviceSize reserved,
                             VkDeviceSize request) noexcept;

// Vulkan's alignments are powers of two; the division is for anything else.
constexpr VkDeviceSize align_up(VkDeviceSize v, VkDeviceSize a) noexcept {
    return (a & (a - 1)) == 0 ? (v + a - 1) & ~(a - 1) : (v + a - 1) / a * a;
}

}  // namespace detail
VKRC_END_NAMESPACE
