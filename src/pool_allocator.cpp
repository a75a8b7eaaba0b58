#include "memory_internal.hpp"

#include <algorithm>
#include <bit>
#include <memory>
#include <string>
#include <vector>

VKRC_BEGIN_NAMESPACE

namespace {

// The PoolAllocator places ranges in blocks with TLSF (two-level segregated
// fit, Masmano et al.): free ranges sit in lists by size class, 16 classes per
// power of two, found through two bitmaps in O(1); a freed range merges with
// its free neighbours at once. Nodes come from a free list, so allocate and
// free touch the heap only when a block is made or released.

constexpr std::uint32_t sl_log = 4;
constexpr std::uint32_t sl_count = 1u << sl_log;
constexpr std::uint32_t fl_count = 64 - sl_log + 1;

struct Block;

// A range of a block, free or used, in the block's address-ordered list.
struct Node {
    VkDeviceSize offset = 0;
    VkDeviceSize size = 0;
    Block* block = nullptr;
    Node* prev_phys = nullptr;  // neighbours in address order
    Node* next_phys = nullptr;
    Node* prev_free = nullptr;  // neighbours in its size class (free nodes only)
    Node* next_free = nullptr;
    bool free = false;
};

struct Pool;

struct Block {
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize size = 0;
    std::byte* mapped = nullptr;
    Pool* pool = nullptr;
    Node* first = nullptr;
    std::uint32_t allocations = 0;
};

// Size class of a free range of size bytes (rounding down).
inline void size_class(VkDeviceSize size, std::uint32_t& fl, std::uint32_t& sl) noexcept {
    if (size < sl_count) {
        fl = 0;
        sl = static_cast<std::uint32_t>(size);
        return;
    }
    const std::uint32_t log = static_cast<std::uint32_t>(std::bit_width(size)) - 1;
    fl = log - sl_log + 1;
    sl = static_cast<std::uint32_t>(size >> (log - sl_log)) - sl_count;
}

// The blocks of one memory type (and, with a large bufferImageGranularity, of
// one tiling class), allocated with or without DEVICE_ADDRESS, and its TLSF index.
struct Pool {
    std::uint32_t memory_type = 0;
    bool device_address = false;  // blocks allocated with VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT
    std::vector<Block*> blocks;
    std::uint64_t fl_bitmap = 0;
    std::uint32_t sl_bitmap[fl_count] = {};
    Node* heads[fl_count][sl_count] = {};

    void insert_free(Node* n) noexcept {
        std::uint32_t fl, sl;
        size_class(n->size, fl, sl);
        n->free = true;
        n->prev_free = nullptr;
        n->next_free = heads[fl][sl];
        if (n->next_free) n->next_free->prev_free = n;
        heads[fl][sl] = n;
        fl_bitmap |= std::uint64_t{1} << fl;
        sl_bitmap[fl] |= 1u << sl;
    }
    void remove_free(Node* n) noexcept {
        std::uint32_t fl, sl;
        size_class(n->size, fl, sl);
        if (n->prev_free) n->prev_free->next_free = n->next_free;
        else heads[fl][sl] = n->next_free;
        if (n->next_free) n->next_free->prev_free = n->prev_free;
        if (!heads[fl][sl]) {
            sl_bitmap[fl] &= ~(1u << sl);
            if (!sl_bitmap[fl]) fl_bitmap &= ~(std::uint64_t{1} << fl);
        }
        n->free = false;
    }
    // A free node of at least size bytes (any in the first non-empty class
    // whose every range is that large), or null.
    Node* find(VkDeviceSize size) const noexcept {
        if (size >= sl_count) {
            // Round up to the next class boundary so every range in it fits.
            const std::uint32_t log = static_cast<std::uint32_t>(std::bit_width(size)) - 1;
            const VkDeviceSize step = VkDeviceSize{1} << (log - sl_log);
            if (size > ~VkDeviceSize{0} - step) return nullptr;
            size += step - 1;
        }
        std::uint32_t fl, sl;
        size_class(size, fl, sl);
        if (fl >= fl_count) return nullptr;
        std::uint32_t sl_map = sl_bitmap[fl] & (~0u << sl);
        if (!sl_map) {
            const std::uint64_t fl_map = fl + 1 < 64 ? fl_bitmap & (~std::uint64_t{0} << (fl + 1)) : 0;
            if (!fl_map) return nullptr;
            fl = static_cast<std::uint32_t>(std::countr_zero(fl_map));
            sl_map = sl_bitmap[fl];
        }
        return heads[fl][std::countr_zero(sl_map)];
    }
    // Tried before find(): the first of a few ranges in size's own class
    // that holds size bytes at the alignment. find() skips that class (not
    // all of its ranges are large enough); using it keeps large free ranges
    // whole, which measurably lowers fragmentation.
    Node* find_in_class(VkDeviceSize size, VkDeviceSize alignment) const noexcept {
        std::uint32_t fl, sl;
        size_class(size, fl, sl);
        if (fl >= fl_count) return nullptr;
        int tries = 4;
        for (Node* n = heads[fl][sl]; n && tries-- > 0; n = n->next_free) {
            if (detail::align_up(n->offset, alignment) - n->offset + size <= n->size) return n;
        }
        return nullptr;
    }
};

// Nodes are recycled through a free list; chunks are freed with the allocator.
class NodeStore {
public:
    ~NodeStore() {
        for (Node* chunk : chunks_) delete[] chunk;
    }
    Node* make() {
        if (!spare_) {
            constexpr std::size_t n = 256;
            Node* chunk = new Node[n];
            try {
                chunks_.push_back(chunk);
            } catch (...) {
                delete[] chunk;
                throw;
            }
            for (std::size_t i = 0; i < n; ++i) recycle(&chunk[i]);
        }
        Node* node = spare_;
        spare_ = node->next_free;
        *node = Node{};
        return node;
    }
    void recycle(Node* node) noexcept {
        node->next_free = spare_;
        spare_ = node;
    }

private:
    std::vector<Node*> chunks_;
    Node* spare_ = nullptr;
};

// Joins node's physical successor (free, out of its size class) to node.
void merge_next_into(Node* node, NodeStore& nodes) noexcept {
    Node* next = node->next_phys;
    node->size += next->size;
    node->next_phys = next->next_phys;
    if (node->next_phys) node->next_phys->prev_phys = node;
    nodes.recycle(next);
}

}  // namespace

struct PoolAllocator::Impl {
    PoolAllocatorCreateInfo info;
    mutable Mutex mutex;
    detail::DeviceState* device = nullptr;  // the device served; null until first use
    // Index: memory type * 4 + 2 * (device-address blocks) + (optimal-tiling
    // pool when kept apart). Device-address blocks are kept apart so that
    // only buffers that ask pay for the flag (drivers may place such memory
    // differently).
    std::unique_ptr<Pool> pools[VK_MAX_MEMORY_TYPES * 4];
    NodeStore nodes;
    AllocatorStatistics stats;
    std::uint32_t memory_objects = 0;  // blocks and dedicated allocations

    VkDeviceSize granularity = 1;
    VkDeviceSize atom = 1;
    VkDeviceSize units[VK_MAX_MEMORY_TYPES] = {};
    std::uint32_t heap_of[VK_MAX_MEMORY_TYPES] = {};
    // bufferImageGranularity up to this is honoured by rounding every range
    // out to it; larger values put linear and optimal resources in separate blocks.
    static constexpr VkDeviceSize max_rounded_granularity = 4096;

    void bind(DeviceView d, const char* who);
    Block& new_block(DeviceView d, Pool& pool, VkDeviceSize at_least);
    void free_block(DeviceView d, Pool& pool, Block& block) noexcept;
    HeapStatistics& heap(std::uint32_t type) noexcept { return stats.heaps[heap_of[type]]; }
};

void PoolAllocator::Impl::bind(DeviceView d, const char* who) {
    if (device == &d.state()) return;
    if (device) throw UsageError(std::string(who) + ": this PoolAllocator serves another device");
    device = &d.state();
    granularity = std::max<VkDeviceSize>(1, d.limits().bufferImageGranularity);
    atom = std::max<VkDeviceSize>(1, d.limits().nonCoherentAtomSize);
    const auto& props = d.memory_properties();
    for (std::uint32_t t = 0; t < props.memoryTypeCount; ++t) {
        // Every range of a memory type starts and ends on a multiple of its
        // unit: the atom on non-coherent memory (so flushes never touch a
        // neighbour's bytes) and a small bufferImageGranularity.
        VkDeviceSize u = granularity <= max_rounded_granularity ? granularity : 1;
        const auto flags = props.memoryTypes[t].propertyFlags;
        if ((flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) && !(flags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT)) {
            u = std::max(u, atom);
        }
        units[t] = u;
        heap_of[t] = props.memoryTypes[t].heapIndex;
    }
}

Block& PoolAllocator::Impl::new_block(DeviceView d, Pool& pool, VkDeviceSize at_least) {
    const auto& props = d.memory_properties();
    const VkDeviceSize heap_size = props.memoryHeaps[heap_of[pool.memory_type]].size;
    // Small heaps get blocks of at most an eighth of the heap.
    const VkDeviceSize max_size = std::min(info.max_block_size, std::max<VkDeviceSize>(heap_size / 8, 1 << 20));
    // A pool grows by about a quarter of its size at a time, between the two limits:
    // small pools waste little in a half-used last block, large ones make
    // few vkAllocateMemory calls.
    VkDeviceSize reserved = 0;
    for (Block* b : pool.blocks) reserved += b->size;
    VkDeviceSize size = std::min(info.min_block_size, max_size);
    while (size < max_size && size * 2 <= reserved / 4) size *= 2;
    size = std::max(size, at_least);
    if (memory_objects >= d.limits().maxMemoryAllocationCount)
        throw Error(VK_ERROR_TOO_MANY_OBJECTS, "vkAllocateMemory");
    auto block = std::make_unique<Block>();
    Node* node = nodes.make();
    try {
        pool.blocks.reserve(pool.blocks.size() + 1);
        try {
            block->memory = detail::allocate_device_memory(d, size, pool.memory_type, VK_NULL_HANDLE, VK_NULL_HANDLE,
                                                           pool.device_address, &block->mapped);
        } catch (const Error& e) {
            // Out of memory for a large block: try one just big enough.
            if (size == at_least ||
                (e.result() != VK_ERROR_OUT_OF_DEVICE_MEMORY && e.result() != VK_ERROR_OUT_OF_HOST_MEMORY)) {
                throw;
            }
            size = at_least;
            block->memory = detail::allocate_device_memory(d, size, pool.memory_type, VK_NULL_HANDLE, VK_NULL_HANDLE,
                                                           pool.device_address, &block->mapped);
        }
    } catch (...) {
        nodes.recycle(node);
        throw;
    }
    stats.vk_allocate_calls += 1;
    block->size = size;
    block->pool = &pool;
    node->size = size;
    node->block = block.get();
    block->first = node;
    pool.insert_free(node);
    pool.blocks.push_back(block.get());
    memory_objects += 1;
    detail::add_block(heap(pool.memory_type), size);
    return *block.release();
}

void PoolAllocator::Impl::free_block(DeviceView d, Pool& pool, Block& block) noexcept {
    for (Node* n = block.first; n;) {
        Node* next = n->next_phys;
        if (n->free) pool.remove_free(n);
        nodes.recycle(n);
        n = next;
    }
    d.fn().vkFreeMemory(d.vk(), block.memory, nullptr);
    detail::remove_block(heap(pool.memory_type), block.size);
    memory_objects -= 1;
    std::erase(pool.blocks, &block);
    delete &block;
}

PoolAllocator::PoolAllocator(const PoolAllocatorCreateInfo& info) : impl_(nullptr) {
    if (info.min_block_size == 0 || info.max_block_size < info.min_block_size) {
        throw UsageError("vkrc::PoolAllocator: min_block_size must be non-zero and at most max_block_size");
    }
    impl_ = new Impl;  // nothing below throws
    impl_->info = info;
    if (impl_->info.dedicated_threshold == 0) impl_->info.dedicated_threshold = info.max_block_size / 2;
}

PoolAllocator::~PoolAllocator() {
    if (impl_->device) release(DeviceView(*impl_->device));
    delete impl_;
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
                                                     request.dedicated_image, request.device_address, &info.mapped);
        info.memory_size = info.size;
        info.dedicated = true;
        m.stats.vk_allocate_calls += 1;
        m.memory_objects += 1;
        detail::add_block(m.heap(type), info.size);
        detail::add_range(m.heap(type), info.size);
        return info;
    }

    const VkDeviceSize unit = m.units[type];
    const VkDeviceSize size = detail::align_up(request.requirements.size, unit);
    const VkDeviceSize alignment = std::max<VkDeviceSize>(request.requirements.alignment, unit);
    const bool separate = m.granularity > Impl::max_rounded_granularity && !request.linear;
    auto& slot = m.pools[type * 4 + (request.device_address ? 2 : 0) + (separate ? 1 : 0)];
    if (!slot) {
        slot = std::make_unique<Pool>();
        slot->memory_type = type;
        slot->device_address = request.device_address;
    }
    Pool& pool = *slot;

    // Every offset is a multiple of unit, so at most alignment - unit bytes
    // of padding go before the range.
    const VkDeviceSize padded = size + (alignment - unit);
    Node* node = pool.find_in_class(size, alignment);
    if (!node) node = pool.find(padded);
    if (!node) node = m.new_block(d, pool, padded).first;
    // Take the nodes the split needs first, so nothing changes if that throws.
    Node* front = nullptr;
    Node* back = nullptr;
    const VkDeviceSize start = detail::align_up(node->offset, alignment);
    const VkDeviceSize front_size = start - node->offset;
    const VkDeviceSize back_size = node->size - front_size - size;
    if (front_size) front = m.nodes.make();
    if (back_size) {
        try {
            back = m.nodes.make();
        } catch (...) {
            if (front) m.nodes.recycle(front);
            throw;
        }
    }
    pool.remove_free(node);
    Block& block = *node->block;
    if (front) {
        // The alignment padding stays free, before the range.
        front->offset = node->offset;
        front->size = front_size;
        front->block = &block;
        front->prev_phys = node->prev_phys;
        front->next_phys = node;
        if (front->prev_phys) front->prev_phys->next_phys = front;
        else block.first = front;
        node->prev_phys = front;
        pool.insert_free(front);
    }
    if (back) {
        back->offset = start + size;
        back->size = back_size;
        back->block = &block;
        back->prev_phys = node;
        back->next_phys = node->next_phys;
        if (back->next_phys) back->next_phys->prev_phys = back;
        node->next_phys = back;
        pool.insert_free(back);
    }
    node->offset = start;
    node->size = size;
    block.allocations += 1;

    info.memory = block.memory;
    info.offset = start;
    info.memory_size = block.size;
    info.mapped = block.mapped ? block.mapped + start : nullptr;
    info.allocator_data = node;
    detail::add_range(m.heap(type), size);
    return info;
}

void PoolAllocator::free(DeviceView d, const AllocationInfo& allocation) {
    if (allocation.allocator != this) {
        throw UsageError("vkrc::PoolAllocator::free: the allocation was made by another allocator");
    }
    auto& m = *impl_;
    LockGuard lock(m.mutex);
    if (m.device != &d.state()) throw UsageError("vkrc::PoolAllocator::free: this PoolAllocator serves another device");
    auto& h = m.heap(allocation.memory_type);
    if (allocation.dedicated) {
        d.fn().vkFreeMemory(d.vk(), allocation.memory, nullptr);
        detail::remove_block(h, allocation.size);
        detail::remove_range(h, allocation.size);
        m.memory_objects -= 1;
        return;
    }
    Node* node = static_cast<Node*>(allocation.allocator_data);
    Block& block = *node->block;
    Pool& pool = *block.pool;
    detail::remove_range(h, node->size);
    block.allocations -= 1;

    // Merge with the free neighbours on both sides.
    if (Node* prev = node->prev_phys; prev && prev->free) {
        pool.remove_free(prev);
        merge_next_into(prev, m.nodes);
        node = prev;
    }
    if (Node* next = node->next_phys; next && next->free) {
        pool.remove_free(next);
        merge_next_into(node, m.nodes);
    }
    pool.insert_free(node);

    if (block.allocations == 0) {
        // Keep one empty block per pool as a spare; release any other (the smaller).
        for (Block* other : pool.blocks) {
            if (other != &block && other->allocations == 0) {
                m.free_block(d, pool, other->size <= block.size ? *other : block);
                break;
            }
        }
    }
}

void PoolAllocator::release(DeviceView d) noexcept {
    auto& m = *impl_;
    LockGuard lock(m.mutex);
    if (m.device != &d.state()) return;
    for (auto& pool : m.pools) {
        if (!pool) continue;
        while (!pool->blocks.empty()) m.free_block(d, *pool, *pool->blocks.back());
        pool.reset();
    }
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
