#include "memory_internal.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <string>
#include <vector>

VKRC_BEGIN_NAMESPACE

namespace {

struct Pool;

// One VkDeviceMemory; its free ranges by offset (for merging neighbours).
struct Block {
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize size = 0;
    std::byte* mapped = nullptr;
    std::uint64_t id = 0;  // orders equal-size free ranges deterministically
    Pool* pool = nullptr;
    std::map<VkDeviceSize, VkDeviceSize> free_ranges;  // offset -> size
    std::uint32_t allocations = 0;
    VkDeviceSize used = 0;
};

// A free range in the pool's best-fit index: smallest size first.
struct FreeKey {
    VkDeviceSize size;
    std::uint64_t block_id;
    VkDeviceSize offset;
    Block* block;
    friend bool operator<(const FreeKey& a, const FreeKey& b) noexcept {
        if (a.size != b.size) return a.size < b.size;
        if (a.block_id != b.block_id) return a.block_id < b.block_id;
        return a.offset < b.offset;
    }
};

// The blocks of one memory type (and, with a large bufferImageGranularity,
// of one tiling class).
struct Pool {
    std::uint32_t memory_type = 0;
    std::vector<std::unique_ptr<Block>> blocks;
    std::set<FreeKey> free_index;
    std::uint32_t blocks_made = 0;  // grows the next block's size
};

}  // namespace

struct PoolAllocator::Impl {
    PoolAllocatorCreateInfo info;
    mutable Mutex mutex;
    detail::DeviceState* device = nullptr;  // the device served; null until first use
    std::map<std::uint32_t, std::unique_ptr<Pool>> pools;  // key: memory type * 2 + non-linear
    AllocatorStatistics stats;
    std::uint64_t next_block_id = 1;
    std::uint32_t memory_objects = 0;  // blocks and dedicated allocations

    VkDeviceSize granularity = 1;
    VkDeviceSize atom = 1;
    // bufferImageGranularity up to this is honoured by rounding every range
    // out to it; larger values put linear and optimal resources in separate blocks.
    static constexpr VkDeviceSize max_rounded_granularity = 4096;

    void bind(DeviceView device, const char* who);
    VkDeviceSize unit(DeviceView d, std::uint32_t type) const noexcept;
    void insert_free(Pool& pool, Block& block, VkDeviceSize offset, VkDeviceSize size);
    void erase_free(Pool& pool, Block& block, std::map<VkDeviceSize, VkDeviceSize>::iterator it);
    Block& new_block(DeviceView device, Pool& pool, VkDeviceSize at_least);
    void free_block(DeviceView device, Pool& pool, Block& block) noexcept;
    HeapStatistics& heap(DeviceView d, std::uint32_t type) {
        return stats.heaps[d.memory_properties().memoryTypes[type].heapIndex];
    }
};

void PoolAllocator::Impl::bind(DeviceView d, const char* who) {
    if (device == &d.state()) return;
    if (device) throw UsageError(std::string(who) + ": this PoolAllocator serves another device");
    device = &d.state();
    granularity = std::max<VkDeviceSize>(1, d.limits().bufferImageGranularity);
    atom = std::max<VkDeviceSize>(1, d.limits().nonCoherentAtomSize);
}

// Every range of a memory type starts and ends on a multiple of this: the
// atom on non-coherent memory (so flushes never touch a neighbour's bytes)
// and a small bufferImageGranularity.
VkDeviceSize PoolAllocator::Impl::unit(DeviceView d, std::uint32_t type) const noexcept {
    VkDeviceSize u = granularity <= max_rounded_granularity ? granularity : 1;
    const auto flags = d.memory_properties().memoryTypes[type].propertyFlags;
    if ((flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) && !(flags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT)) {
        u = std::max(u, atom);
    }
    return u;
}

void PoolAllocator::Impl::insert_free(Pool& pool, Block& block, VkDeviceSize offset, VkDeviceSize size) {
    if (size == 0) return;
    block.free_ranges.emplace(offset, size);
    pool.free_index.insert(FreeKey{size, block.id, offset, &block});
}

void PoolAllocator::Impl::erase_free(Pool& pool, Block& block, std::map<VkDeviceSize, VkDeviceSize>::iterator it) {
    pool.free_index.erase(FreeKey{it->second, block.id, it->first, &block});
    block.free_ranges.erase(it);
}

Block& PoolAllocator::Impl::new_block(DeviceView d, Pool& pool, VkDeviceSize at_least) {
    const auto& props = d.memory_properties();
    const VkDeviceSize heap_size = props.memoryHeaps[props.memoryTypes[pool.memory_type].heapIndex].size;
    // Small heaps (below 2 GiB) get blocks of at most an eighth of the heap.
    VkDeviceSize max_size = std::min(info.max_block_size, std::max<VkDeviceSize>(heap_size / 8, 1 << 20));
    VkDeviceSize size = std::min(info.min_block_size, max_size);
    for (std::uint32_t i = 0; i < pool.blocks_made && size < max_size; ++i) size = std::min(size * 2, max_size);
    size = std::max(size, at_least);
    if (memory_objects >= d.limits().maxMemoryAllocationCount) throw Error(VK_ERROR_TOO_MANY_OBJECTS, "vkAllocateMemory");
    auto block = std::make_unique<Block>();
    try {
        block->memory = detail::allocate_device_memory(d, size, pool.memory_type, VK_NULL_HANDLE, VK_NULL_HANDLE,
                                                       &block->mapped);
    } catch (const Error& e) {
        // Out of memory for a large block: try one just big enough.
        if (size == at_least || (e.result() != VK_ERROR_OUT_OF_DEVICE_MEMORY && e.result() != VK_ERROR_OUT_OF_HOST_MEMORY)) {
            throw;
        }
        size = at_least;
        block->memory = detail::allocate_device_memory(d, size, pool.memory_type, VK_NULL_HANDLE, VK_NULL_HANDLE,
                                                       &block->mapped);
    }
    stats.vk_allocate_calls += 1;
    block->size = size;
    block->id = next_block_id++;
    block->pool = &pool;
    Block& b = *block;
    try {
        pool.blocks.push_back(std::move(block));
    } catch (...) {
        d.fn().vkFreeMemory(d.vk(), b.memory, nullptr);
        throw;
    }
    insert_free(pool, b, 0, size);
    pool.blocks_made += 1;
    memory_objects += 1;
    auto& h = heap(d, pool.memory_type);
    h.block_bytes += size;
    h.block_count += 1;
    return b;
}

void PoolAllocator::Impl::free_block(DeviceView d, Pool& pool, Block& block) noexcept {
    for (auto it = block.free_ranges.begin(); it != block.free_ranges.end();) {
        auto next = std::next(it);
        erase_free(pool, block, it);
        it = next;
    }
    d.fn().vkFreeMemory(d.vk(), block.memory, nullptr);
    auto& h = heap(d, pool.memory_type);
    h.block_bytes -= block.size;
    h.block_count -= 1;
    memory_objects -= 1;
    std::erase_if(pool.blocks, [&](const std::unique_ptr<Block>& b) { return b.get() == &block; });
}

PoolAllocator::PoolAllocator(const PoolAllocatorCreateInfo& info) : impl_(std::make_unique<Impl>()) {
    if (info.min_block_size == 0 || info.max_block_size < info.min_block_size) {
        throw UsageError("vkrc::PoolAllocator: min_block_size must be non-zero and at most max_block_size");
    }
    impl_->info = info;
    if (impl_->info.dedicated_threshold == 0) impl_->info.dedicated_threshold = info.max_block_size / 2;
}

PoolAllocator::~PoolAllocator() {
    if (impl_->device) release(DeviceView(*impl_->device));
}

AllocationInfo PoolAllocator::allocate(DeviceView d, const AllocationRequest& request) {
    constexpr const char* who = "vkrc::PoolAllocator::allocate";
    const auto& props = d.memory_properties();
    const std::uint32_t type = choose_memory_type(props, request.requirements.memoryTypeBits, request.intent, who);
    detail::check_request(d, request, type, who);
    auto& m = *impl_;
    LockGuard lock(m.mutex);
    m.bind(d, who);

    AllocationInfo info;
    info.size = request.requirements.size;
    info.memory_type = type;
    info.allocator = this;

    const bool dedicated = request.requires_dedicated || request.prefers_dedicated || request.intent.dedicated ||
                           request.requirements.size > m.info.dedicated_threshold;
    if (dedicated) {
        if (m.memory_objects >= d.limits().maxMemoryAllocationCount) {
            throw Error(VK_ERROR_TOO_MANY_OBJECTS, "vkAllocateMemory");
        }
        info.memory = detail::allocate_device_memory(d, info.size, type, request.dedicated_buffer,
                                                     request.dedicated_image, &info.mapped);
        info.memory_size = info.size;
        info.dedicated = true;
        m.stats.vk_allocate_calls += 1;
        m.memory_objects += 1;
        auto& h = m.heap(d, type);
        h.block_bytes += info.size;
        h.allocation_bytes += info.size;
        h.block_count += 1;
        h.allocation_count += 1;
        return info;
    }

    const VkDeviceSize unit = m.unit(d, type);
    const VkDeviceSize size = detail::align_up(request.requirements.size, unit);
    const VkDeviceSize alignment = std::max<VkDeviceSize>({request.requirements.alignment, unit, 1});
    const bool separate = m.granularity > Impl::max_rounded_granularity && !request.linear;
    auto& slot = m.pools[type * 2 + (separate ? 1 : 0)];
    if (!slot) {
        slot = std::make_unique<Pool>();
        slot->memory_type = type;
    }
    Pool& pool = *slot;

    // Best fit: the smallest free range that holds size at the alignment.
    // A few exact-size candidates are tried, then the first range that fits
    // whatever its alignment padding.
    auto fits = [&](const FreeKey& k) {
        const VkDeviceSize start = detail::align_up(k.offset, alignment);
        return start - k.offset + size <= k.size;
    };
    auto it = pool.free_index.lower_bound(FreeKey{size, 0, 0, nullptr});
    for (int tries = 0; it != pool.free_index.end() && tries < 8 && !fits(*it); ++tries) ++it;
    if (it != pool.free_index.end() && !fits(*it)) {
        it = pool.free_index.lower_bound(FreeKey{size + alignment - 1, 0, 0, nullptr});
    }
    Block* block = nullptr;
    VkDeviceSize range_offset = 0;
    VkDeviceSize range_size = 0;
    if (it != pool.free_index.end()) {
        block = it->block;
        range_offset = it->offset;
        range_size = it->size;
    } else {
        block = &m.new_block(d, pool, size);
        range_offset = 0;
        range_size = block->size;
    }
    m.erase_free(pool, *block, block->free_ranges.find(range_offset));
    const VkDeviceSize start = detail::align_up(range_offset, alignment);
    // The alignment padding and the tail stay free (the padding is a multiple of unit).
    m.insert_free(pool, *block, range_offset, start - range_offset);
    m.insert_free(pool, *block, start + size, range_offset + range_size - (start + size));
    block->allocations += 1;
    block->used += size;

    info.memory = block->memory;
    info.offset = start;
    info.memory_size = block->size;
    info.mapped = block->mapped ? block->mapped + start : nullptr;
    info.allocator_data = block;
    auto& h = m.heap(d, type);
    h.allocation_bytes += size;
    h.allocation_count += 1;
    return info;
}

void PoolAllocator::free(DeviceView d, const AllocationInfo& allocation) {
    if (allocation.allocator != this) {
        throw UsageError("vkrc::PoolAllocator::free: the allocation was made by another allocator");
    }
    auto& m = *impl_;
    LockGuard lock(m.mutex);
    if (m.device != &d.state()) throw UsageError("vkrc::PoolAllocator::free: this PoolAllocator serves another device");
    auto& h = m.heap(d, allocation.memory_type);
    if (allocation.dedicated) {
        d.fn().vkFreeMemory(d.vk(), allocation.memory, nullptr);
        h.block_bytes -= allocation.size;
        h.allocation_bytes -= allocation.size;
        h.block_count -= 1;
        h.allocation_count -= 1;
        m.memory_objects -= 1;
        return;
    }
    auto& block = *static_cast<Block*>(allocation.allocator_data);
    auto& pool = *block.pool;
    VkDeviceSize offset = allocation.offset;
    VkDeviceSize size = detail::align_up(allocation.size, m.unit(d, allocation.memory_type));
    block.allocations -= 1;
    block.used -= size;
    h.allocation_bytes -= size;
    h.allocation_count -= 1;

    // Merge with the free neighbours on both sides.
    auto next = block.free_ranges.lower_bound(offset);
    if (next != block.free_ranges.begin()) {
        auto prev = std::prev(next);
        if (prev->first + prev->second == offset) {
            offset = prev->first;
            size += prev->second;
            m.erase_free(pool, block, prev);
        }
    }
    if (next != block.free_ranges.end() && next->first == offset + size) {
        size += next->second;
        m.erase_free(pool, block, next);
    }
    m.insert_free(pool, block, offset, size);

    if (block.allocations == 0) {
        // Keep one empty block per pool as a spare; release any other.
        for (auto& other : pool.blocks) {
            if (other.get() != &block && other->allocations == 0) {
                Block& victim = other->size <= block.size ? *other : block;
                m.free_block(d, pool, victim);
                break;
            }
        }
    }
}

void PoolAllocator::release(DeviceView d) noexcept {
    auto& m = *impl_;
    LockGuard lock(m.mutex);
    if (m.device != &d.state()) return;
    for (auto& [key, pool] : m.pools) {
        while (!pool->blocks.empty()) m.free_block(d, *pool, *pool->blocks.back());
    }
    m.pools.clear();
    m.stats = {};
    m.memory_objects = 0;
    m.device = nullptr;
}

AllocatorStatistics PoolAllocator::statistics(DeviceView d) const {
    AllocatorStatistics stats;
    {
        LockGuard lock(impl_->mutex);
        stats = impl_->stats;
    }
    fill_budget(d, stats);
    return stats;
}

VKRC_END_NAMESPACE
