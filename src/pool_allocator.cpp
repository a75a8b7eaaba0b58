#include "memory_internal.hpp"

#include <algorithm>
#include <bit>
#include <memory>
#include <string>
#include <thread>
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
struct Shard;

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
    Shard* shard = nullptr;  // the owner; free() locks it
    std::uint32_t memory_type = 0;
    bool device_address = false;  // blocks allocated with VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT
    std::vector<Block*> blocks;
    VkDeviceSize reserved = 0;  // bytes of its blocks
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

// Puts front, a free range of size bytes, before node, at node's offset.
void link_free_before(Pool& pool, Node& node, Node& front, VkDeviceSize size) noexcept {
    front.offset = node.offset;
    front.size = size;
    front.block = node.block;
    front.prev_phys = node.prev_phys;
    front.next_phys = &node;
    if (front.prev_phys) front.prev_phys->next_phys = &front;
    else node.block->first = &front;
    node.prev_phys = &front;
    pool.insert_free(&front);
}

// Puts back, a free range of size bytes at offset, after node.
void link_free_after(Pool& pool, Node& node, Node& back, VkDeviceSize offset, VkDeviceSize size) noexcept {
    back.offset = offset;
    back.size = size;
    back.block = node.block;
    back.prev_phys = &node;
    back.next_phys = node.next_phys;
    if (back.next_phys) back.next_phys->prev_phys = &back;
    node.next_phys = &back;
    pool.insert_free(&back);
}

// Makes node, a free range, the used range [start, start + size): the
// alignment padding before it and the rest after it stay free, as nodes of their own.
void carve(Pool& pool, NodeStore& nodes, Node& node, VkDeviceSize start, VkDeviceSize size) {
    const VkDeviceSize front_size = start - node.offset;
    const VkDeviceSize back_size = node.size - front_size - size;
    // Take the nodes the split needs first, so nothing changes if that throws.
    Node* front = front_size ? nodes.make() : nullptr;
    Node* back = nullptr;
    if (back_size) {
        try {
            back = nodes.make();
        } catch (...) {
            if (front) nodes.recycle(front);
            throw;
        }
    }
    pool.remove_free(&node);
    if (front) link_free_before(pool, node, *front, front_size);
    if (back) link_free_after(pool, node, *back, start + size, back_size);
    node.offset = start;
    node.size = size;
    node.block->allocations += 1;
}

// Which allocations of a host-visible memory type may share a block. The
// host writes upload ranges and the GPU writes gpu_only and readback ones, so
// they never share a (mapped) block: a capture layer such as gfxreconstruct
// tracks host writes by page and copies each written page whole to the
// device memory at submit, which overwrote GPU-written bytes in the same
// page (issue 34: the teapot's frames under capture). custom, whose writer
// vkrc cannot know, keeps to itself too. Memory types that are not
// host-visible have one class (nothing maps them).
enum class HostAccess : std::uint32_t { gpu_written, host_written, unknown };
constexpr std::uint32_t host_access_count = 3;
constexpr HostAccess host_access(MemoryUsage usage) noexcept {
    switch (usage) {
        case MemoryUsage::upload: return HostAccess::host_written;
        case MemoryUsage::custom: return HostAccess::unknown;
        case MemoryUsage::gpu_only:
        case MemoryUsage::readback: break;
    }
    return HostAccess::gpu_written;
}

// An independent part of a PoolAllocator: its own lock, pools (so blocks and
// spares) and nodes. Its statistics are summed by statistics().
struct alignas(64) Shard {  // apart in cache: threads on different shards share no line
    Mutex mutex;
    // Index: ((memory type * host_access_count + host access class) * 2 +
    // device-address blocks) * 2 + optimal-tiling pool when kept apart.
    // Device-address blocks are kept apart so that only buffers that ask pay
    // for the flag (drivers may place such memory differently).
    std::unique_ptr<Pool> pools[VK_MAX_MEMORY_TYPES * host_access_count * 4];
    NodeStore nodes;
    AllocatorStatistics stats;
};

// Unlocks a shard locked by PoolAllocator::Impl::lock_shard.
class ShardLock {
public:
    explicit ShardLock(Shard& shard) noexcept : shard_(shard) {}
    ShardLock(const ShardLock&) = delete;
    ShardLock& operator=(const ShardLock&) = delete;
    ~ShardLock() { shard_.mutex.unlock(); }

private:
    Shard& shard_;
};

#if VKRC_IS_MULTI_THREAD
// Threads take home shards round-robin, in the order of their first allocation.
detail::Atomic<std::uint32_t> next_thread{0};
thread_local std::uint32_t thread_ticket = 0;  // 0: none yet; else 1 + the thread's number

std::uint32_t thread_number() noexcept {
    if (thread_ticket == 0) thread_ticket = next_thread.fetch_add(1, __ATOMIC_RELAXED) + 1;
    return thread_ticket - 1;
}
#endif

std::uint32_t resolve_shards(std::uint32_t wanted) noexcept {
#if VKRC_IS_MULTI_THREAD
    if (wanted != 0) return wanted;
    return std::clamp<std::uint32_t>(std::thread::hardware_concurrency(), 1, max_pool_shards);
#else
    (void)wanted;
    return 1;  // one thread at a time gains nothing from more
#endif
}

}  // namespace

namespace detail {

VkDeviceSize next_block_size(const PoolAllocatorCreateInfo& info, VkDeviceSize heap_size, VkDeviceSize reserved,
                             VkDeviceSize request) noexcept {
    // Small heaps get blocks of at most an eighth of the heap.
    const VkDeviceSize cap = std::min(info.max_block_size, std::max<VkDeviceSize>(heap_size / 8, 1 << 20));
    // Twice the request (as VMA), so that its like fits beside it; a request
    // above half the cap gets a block of its own size.
    const VkDeviceSize room = request > cap / 2 ? request : request * 2;
    const VkDeviceSize wanted = std::max(room, reserved / pool_growth_divisor);
    VkDeviceSize size = std::min(info.min_block_size, cap);
    while (size < cap && size < wanted) size *= 2;
    return std::max(std::min(size, cap), request);
}

}  // namespace detail

struct PoolAllocator::Impl {
    PoolAllocatorCreateInfo info;
    std::unique_ptr<Shard[]> shards;
    std::uint32_t shard_count = 1;
    // The device served; null until first use. Set once under bind_mutex;
    // the limits below are written before it and read after it.
    detail::Atomic<detail::DeviceState*> device{nullptr};
    Mutex bind_mutex;
    // Blocks and dedicated allocations of all shards, against maxMemoryAllocationCount.
    detail::Atomic<std::uint32_t> memory_objects{0};

    VkDeviceSize granularity = 1;
    VkDeviceSize atom = 1;
    VkDeviceSize units[VK_MAX_MEMORY_TYPES] = {};
    std::uint32_t heap_of[VK_MAX_MEMORY_TYPES] = {};
    bool host_visible[VK_MAX_MEMORY_TYPES] = {};
    // bufferImageGranularity up to this is honoured by rounding every range
    // out to it; larger values put linear and optimal resources in separate blocks.
    static constexpr VkDeviceSize max_rounded_granularity = 4096;

    void bind(DeviceView d, const detail::Caller& caller);
    Shard& lock_shard() noexcept;
    void count_memory_object(DeviceView d);
    Block& new_block(DeviceView d, Shard& shard, Pool& pool, VkDeviceSize at_least);
    void free_block(DeviceView d, Shard& shard, Pool& pool, Block& block) noexcept;
    void release_spare(DeviceView d, Shard& shard, Pool& pool) noexcept;
    // allocate()'s two paths; out arrives with size and memory_type set.
    void allocate_dedicated(DeviceView d, const AllocationRequest& request, AllocationInfo& out);
    void allocate_range(DeviceView d, const AllocationRequest& request, AllocationInfo& out);
    Pool& pool_for(Shard& shard, std::uint32_t type, const AllocationRequest& request);
    HeapStatistics& heap(Shard& shard, std::uint32_t type) noexcept { return shard.stats.heaps[heap_of[type]]; }
};

void PoolAllocator::Impl::bind(DeviceView d, const detail::Caller& caller) {
    if (device.load(__ATOMIC_ACQUIRE) == &d.state()) return;
    LockGuard lock(bind_mutex);
    detail::DeviceState* now = device.load(__ATOMIC_ACQUIRE);
    if (now == &d.state()) return;
    caller.require(!now, "this PoolAllocator serves another device");
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
        host_visible[t] = (flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) != 0;
    }
    device.store(&d.state(), __ATOMIC_RELEASE);
}

// The calling thread's home shard if its lock is free, else the next free
// one, else (all busy) the home shard once it is free. Returned locked.
Shard& PoolAllocator::Impl::lock_shard() noexcept {
#if VKRC_IS_MULTI_THREAD
    if (shard_count > 1) {
        const std::uint32_t home = thread_number() % shard_count;
        for (std::uint32_t i = 0; i < shard_count; ++i) {
            Shard& s = shards[(home + i) % shard_count];
            if (s.mutex.try_lock()) return s;
        }
        shards[home].mutex.lock();
        return shards[home];
    }
#endif
    shards[0].mutex.lock();
    return shards[0];
}

// Counts one more VkDeviceMemory, or throws when the device allows no more.
void PoolAllocator::Impl::count_memory_object(DeviceView d) {
    if (memory_objects.fetch_add(1, __ATOMIC_RELAXED) >= d.limits().maxMemoryAllocationCount) {
        memory_objects.fetch_sub(1, __ATOMIC_RELAXED);
        throw Error(VK_ERROR_TOO_MANY_OBJECTS, "vkAllocateMemory");
    }
}

Block& PoolAllocator::Impl::new_block(DeviceView d, Shard& shard, Pool& pool, VkDeviceSize at_least) {
    const VkDeviceSize heap_size = d.memory_properties().memoryHeaps[heap_of[pool.memory_type]].size;
    VkDeviceSize size = detail::next_block_size(info, heap_size, pool.reserved, at_least);
    auto block = std::make_unique<Block>();
    count_memory_object(d);
    Node* node = nullptr;
    try {
        node = shard.nodes.make();
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
        if (node) shard.nodes.recycle(node);
        memory_objects.fetch_sub(1, __ATOMIC_RELAXED);
        throw;
    }
    shard.stats.vk_allocate_calls += 1;
    block->size = size;
    block->pool = &pool;
    node->size = size;
    node->block = block.get();
    block->first = node;
    pool.insert_free(node);
    pool.blocks.push_back(block.get());
    pool.reserved += size;
    detail::add_block(heap(shard, pool.memory_type), size);
    return *block.release();
}

void PoolAllocator::Impl::free_block(DeviceView d, Shard& shard, Pool& pool, Block& block) noexcept {
    for (Node* n = block.first; n;) {
        Node* next = n->next_phys;
        if (n->free) pool.remove_free(n);
        shard.nodes.recycle(n);
        n = next;
    }
    d.fn().vkFreeMemory(d.vk(), block.memory, nullptr);
    detail::remove_block(heap(shard, pool.memory_type), block.size);
    pool.reserved -= block.size;
    memory_objects.fetch_sub(1, __ATOMIC_RELAXED);
    std::erase(pool.blocks, &block);
    delete &block;
}

// Called when a block of pool has emptied: with more than spare_blocks
// empty blocks, the smallest goes. A program that loads and drops resources
// swings by more than one block (an eighth of a large pool), and a block
// freed and made again costs a vkAllocateMemory (and a map) each time.
void PoolAllocator::Impl::release_spare(DeviceView d, Shard& shard, Pool& pool) noexcept {
    std::uint32_t empty = 0;
    Block* smallest = nullptr;
    for (Block* b : pool.blocks) {
        if (b->allocations != 0) continue;
        ++empty;
        if (!smallest || b->size < smallest->size) smallest = b;
    }
    if (empty > info.spare_blocks) free_block(d, shard, pool, *smallest);
}

// A VkDeviceMemory of its own, counted in the statistics of a shard.
void PoolAllocator::Impl::allocate_dedicated(DeviceView d, const AllocationRequest& request, AllocationInfo& out) {
    // No shard's lock is held while the driver allocates.
    count_memory_object(d);
    try {
        out.memory = detail::allocate_device_memory(d, out.size, out.memory_type, request.dedicated_buffer,
                                                    request.dedicated_image, request.device_address, &out.mapped);
    } catch (...) {
        memory_objects.fetch_sub(1, __ATOMIC_RELAXED);
        throw;
    }
    out.memory_size = out.size;
    out.dedicated = true;
    Shard& shard = lock_shard();
    ShardLock lock(shard);
    out.allocator_data = &shard;  // whose statistics count it
    shard.stats.vk_allocate_calls += 1;
    detail::add_block(heap(shard, out.memory_type), out.size);
    detail::add_range(heap(shard, out.memory_type), out.size);
}

// A range of a block in the calling thread's shard: a free range that fits, else a new block.
void PoolAllocator::Impl::allocate_range(DeviceView d, const AllocationRequest& request, AllocationInfo& out) {
    const std::uint32_t type = out.memory_type;
    Shard& shard = lock_shard();
    ShardLock lock(shard);
    const VkDeviceSize unit = units[type];
    const VkDeviceSize size = detail::align_up(request.requirements.size, unit);
    const VkDeviceSize alignment = std::max<VkDeviceSize>(request.requirements.alignment, unit);
    Pool& pool = pool_for(shard, type, request);

    // Every offset is a multiple of unit, so at most alignment - unit bytes
    // of padding go before the range.
    const VkDeviceSize padded = size + (alignment - unit);
    Node* node = pool.find_in_class(size, alignment);
    if (!node) node = pool.find(padded);
    if (!node) node = new_block(d, shard, pool, padded).first;
    const VkDeviceSize start = detail::align_up(node->offset, alignment);
    carve(pool, shard.nodes, *node, start, size);

    const Block& block = *node->block;
    out.memory = block.memory;
    out.offset = start;
    out.memory_size = block.size;
    out.mapped = block.mapped ? block.mapped + start : nullptr;
    out.allocator_data = node;
    detail::add_range(heap(shard, type), size);
}

// The shard's pool for the request's memory type and kind of block, made on first use.
Pool& PoolAllocator::Impl::pool_for(Shard& shard, std::uint32_t type, const AllocationRequest& request) {
    const bool separate = granularity > max_rounded_granularity && !request.linear;
    const auto access = host_visible[type] ? static_cast<std::uint32_t>(host_access(request.intent.usage)) : 0;
    auto& slot =
        shard.pools[(type * host_access_count + access) * 4 + (request.device_address ? 2 : 0) + (separate ? 1 : 0)];
    if (!slot) {
        slot = std::make_unique<Pool>();
        slot->shard = &shard;
        slot->memory_type = type;
        slot->device_address = request.device_address;
    }
    return *slot;
}

PoolAllocator::PoolAllocator(const PoolAllocatorCreateInfo& info) : impl_(nullptr) {
    const detail::Caller caller{"vkrc::PoolAllocator"};
    caller.require(info.min_block_size != 0 && info.max_block_size >= info.min_block_size, "min_block_size ",
                   info.min_block_size, " and max_block_size ", info.max_block_size,
                   ": min_block_size must be non-zero and at most max_block_size");
    caller.require(info.shards <= max_pool_shards, "shards is ", info.shards, ", more than ", max_pool_shards);
    auto impl = std::make_unique<Impl>();
    impl->info = info;
    if (impl->info.dedicated_threshold == 0) impl->info.dedicated_threshold = info.max_block_size / 2;
    impl->shard_count = resolve_shards(info.shards);
    impl->shards = std::make_unique<Shard[]>(impl->shard_count);
    impl_ = impl.release();
}

PoolAllocator::~PoolAllocator() {
    if (detail::DeviceState* d = impl_->device.load(__ATOMIC_ACQUIRE)) release(DeviceView(*d));
    delete impl_;
}

std::uint32_t PoolAllocator::shard_count() const noexcept { return impl_->shard_count; }

AllocationInfo PoolAllocator::allocate(DeviceView d, const AllocationRequest& request) {
    const detail::Caller caller{"vkrc::PoolAllocator::allocate"};
    const std::uint32_t type = detail::checked_memory_type(caller, d, request);
    auto& m = *impl_;
    m.bind(d, caller);

    AllocationInfo info;
    info.size = request.requirements.size;
    info.memory_type = type;
    info.allocator = this;

    const bool dedicated = request.requires_dedicated || request.prefers_dedicated || request.intent.dedicated ||
                           request.requirements.size > m.info.dedicated_threshold;
    if (dedicated) m.allocate_dedicated(d, request, info);
    else m.allocate_range(d, request, info);
    return info;
}

void PoolAllocator::free(DeviceView d, const AllocationInfo& allocation) {
    const detail::Caller caller{"vkrc::PoolAllocator::free"};
    caller.require(allocation.allocator == this, "the allocation was made by another allocator");
    auto& m = *impl_;
    caller.require(m.device.load(__ATOMIC_ACQUIRE) == &d.state(), "this PoolAllocator serves another device");
    if (allocation.dedicated) {
        d.fn().vkFreeMemory(d.vk(), allocation.memory, nullptr);
        m.memory_objects.fetch_sub(1, __ATOMIC_RELAXED);
        Shard& shard = *static_cast<Shard*>(allocation.allocator_data);
        LockGuard lock(shard.mutex);
        auto& h = m.heap(shard, allocation.memory_type);
        detail::remove_block(h, allocation.size);
        detail::remove_range(h, allocation.size);
        return;
    }
    // The range's node and block do not change while it is allocated, so
    // its shard can be read before taking that shard's lock.
    Node* node = static_cast<Node*>(allocation.allocator_data);
    Block& block = *node->block;
    Pool& pool = *block.pool;
    Shard& shard = *pool.shard;
    LockGuard lock(shard.mutex);
    detail::remove_range(m.heap(shard, allocation.memory_type), node->size);
    block.allocations -= 1;

    // Merge with the free neighbours on both sides.
    if (Node* prev = node->prev_phys; prev && prev->free) {
        pool.remove_free(prev);
        merge_next_into(prev, shard.nodes);
        node = prev;
    }
    if (Node* next = node->next_phys; next && next->free) {
        pool.remove_free(next);
        merge_next_into(node, shard.nodes);
    }
    pool.insert_free(node);

    if (block.allocations == 0) {
        m.release_spare(d, shard, pool);
    }
}

void PoolAllocator::release(DeviceView d) noexcept {
    auto& m = *impl_;
    LockGuard bind_lock(m.bind_mutex);
    if (m.device.load(__ATOMIC_ACQUIRE) != &d.state()) return;
    for (std::uint32_t i = 0; i < m.shard_count; ++i) {
        Shard& shard = m.shards[i];
        LockGuard lock(shard.mutex);
        for (auto& pool : shard.pools) {
            if (!pool) continue;
            while (!pool->blocks.empty()) m.free_block(d, shard, *pool, *pool->blocks.back());
            pool.reset();
        }
        shard.stats = {};
    }
    m.memory_objects.store(0, __ATOMIC_RELAXED);
    m.device.store(nullptr, __ATOMIC_RELEASE);
}

AllocatorStatistics PoolAllocator::statistics(DeviceView d) const {
    AllocatorStatistics stats;
    for (std::uint32_t i = 0; i < impl_->shard_count; ++i) {
        Shard& shard = impl_->shards[i];
        LockGuard lock(shard.mutex);
        stats.vk_allocate_calls += shard.stats.vk_allocate_calls;
        for (std::uint32_t h = 0; h < VK_MAX_MEMORY_HEAPS; ++h)
            detail::add_tallies(stats.heaps[h], shard.stats.heaps[h]);
    }
    fill_budget(d, stats);
    return stats;
}

VKRC_END_NAMESPACE
