// Device memory: the allocator interface, the two allocators vkrc ships,
// allocations and mapped-memory access.
//
// An allocator hands out AllocationInfo values (a range of a VkDeviceMemory);
// an Allocation owns one of them, keeps its Device alive and returns the
// range to its allocator, after the GPU is done with it, when its last owner
// goes. Allocation and free are cold paths (virtual calls, locks); mapped
// reads and writes are inline memcpy.
#pragma once

#include "vkrc/device.hpp"

#include <cstddef>
#include <cstring>

VKRC_BEGIN_NAMESPACE

class DeviceAllocator;

// What the memory of a resource is for; picks the memory type.
enum class MemoryUsage : std::uint8_t {
    gpu_only,  // device-local, not mapped
    upload,    // host-visible, written by the CPU once and read by the GPU (staging, per-frame data)
    readback,  // host-visible, preferably cached: written by the GPU, read by the CPU
    custom,    // only required_flags / preferred_flags decide
};

// The intent of a resource's memory.
// Every member is optional.
struct MemoryIntent {
    // Default gpu_only.
    MemoryUsage usage = MemoryUsage::gpu_only;
    // Added to what the usage requires / prefers (default none).
    VkMemoryPropertyFlags required_flags = 0;
    VkMemoryPropertyFlags preferred_flags = 0;
    // Always its own VkDeviceMemory (the driver may also ask for it). Default false.
    bool dedicated = false;
};

// Everything an allocator needs to place one resource.
// Buffer::create and Image::create fill it; Allocation::create takes one from the caller.
struct AllocationRequest {
    // Required: size non-zero, memoryTypeBits from the resource.
    VkMemoryRequirements requirements{};
    // Optional (default: GPU-only memory).
    MemoryIntent intent{};
    // From VkMemoryDedicatedRequirements (Vulkan 1.1 core). Optional (default false).
    bool prefers_dedicated = false;
    bool requires_dedicated = false;
    // The resource, for VkMemoryDedicatedAllocateInfo when dedicated; at most one set.
    // Optional (default none); only the handle is passed on, during allocate().
    VkBuffer dedicated_buffer = VK_NULL_HANDLE;
    VkImage dedicated_image = VK_NULL_HANDLE;
    // Buffers and linear images are "linear"; optimal-tiling images are not
    // (bufferImageGranularity separates the two). Optional (default true).
    bool linear = true;
    // The memory must be allocated with VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT
    // (VkMemoryAllocateFlagsInfo): Buffer::create sets it for buffers with
    // SHADER_DEVICE_ADDRESS usage, and an allocator must honour it (the
    // bufferDeviceAddress feature is then enabled). Optional (default false).
    bool device_address = false;
};

// A range of device memory as an allocator describes it.
struct AllocationInfo {
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize offset = 0;       // of the range in memory
    VkDeviceSize size = 0;         // usable bytes, at least the requested size
    VkDeviceSize memory_size = 0;  // of the whole VkDeviceMemory (the block)
    std::uint32_t memory_type = 0;
    std::byte* mapped = nullptr;  // host address of offset; null when not host-visible
    bool dedicated = false;       // the range is the whole of its own VkDeviceMemory
    // Set by the allocator that made the range; free checks it.
    const DeviceAllocator* allocator = nullptr;
    void* allocator_data = nullptr;  // the allocator's own bookkeeping
};

// A non-owning view of a device for allocator calls: an allocator the device
// keeps must not hold a Device handle (that would be a reference cycle).
class DeviceView {
public:
    explicit DeviceView(detail::DeviceState& state) noexcept : s_(&state) {}
    VkDevice vk() const noexcept { return s_->device; }
    const DeviceFunctions& fn() const noexcept { return s_->fn; }
    const PhysicalDevice& physical_device() const noexcept { return s_->physical_device; }
    const VkPhysicalDeviceMemoryProperties& memory_properties() const noexcept {
        return s_->physical_device.memory_properties();
    }
    const VkPhysicalDeviceLimits& limits() const noexcept { return s_->physical_device.properties().limits; }
    bool extension_enabled(const char* name) const noexcept;
    detail::DeviceState& state() const noexcept { return *s_; }
    friend bool operator==(DeviceView a, DeviceView b) noexcept { return a.s_ == b.s_; }

private:
    detail::DeviceState* s_;
};

// Per heap: what an allocator holds and hands out, and the driver's budget.
struct HeapStatistics {
    VkDeviceSize block_bytes = 0;       // reserved with vkAllocateMemory
    VkDeviceSize allocation_bytes = 0;  // handed out to resources
    std::uint32_t block_count = 0;      // VkDeviceMemory objects
    std::uint32_t allocation_count = 0;
    // VK_EXT_memory_budget when enabled, else the heap size and block_bytes.
    VkDeviceSize budget = 0;
    VkDeviceSize usage = 0;
};

struct AllocatorStatistics {
    HeapStatistics heaps[VK_MAX_MEMORY_HEAPS]{};
    std::uint32_t heap_count = 0;
    std::uint64_t vk_allocate_calls = 0;  // vkAllocateMemory calls made so far
    HeapStatistics total() const noexcept;
};

// The pluggable allocator. Implementations allocate and free ranges; vkrc
// calls them on cold paths only. The device keeps every allocator used with
// it until its own teardown (so that deferred frees can run), then calls
// release(). Thread safety under the multi-thread policy is the allocator's.
// Allocators are shared through SharedAllocator (make one with
// make_allocator), reference-counted like every vkrc object.
class DeviceAllocator : public detail::RefCounted {
public:
    virtual ~DeviceAllocator() = default;
    // Returns a range with info.allocator == this, or throws (vkrc::Error,
    // vkrc::UsageError). Memory types are chosen with choose_memory_type.
    virtual AllocationInfo allocate(DeviceView device, const AllocationRequest& request) = 0;
    // Takes back a range this allocator made. Throws UsageError for a range
    // from another allocator (and frees nothing).
    virtual void free(DeviceView device, const AllocationInfo& allocation) = 0;
    // The device is being destroyed and every range made on it was freed:
    // give back what is cached.
    virtual void release(DeviceView device) noexcept { (void)device; }
    virtual AllocatorStatistics statistics(DeviceView device) const;
};

// Shared ownership of an allocator; empty means the device's default.
using SharedAllocator = detail::Ref<DeviceAllocator>;

// Names the allocator of one create call without owning it (empty: the
// device's default). The caller's SharedAllocator keeps it alive through the
// call and the device keeps it from then on, so naming a shared allocator
// writes no reference count: a count that every creating thread increments
// is one cache line they all contend for. Made from a named SharedAllocator
// only: one made from a temporary would dangle in a create-info kept past
// the statement.
class AllocatorView {
public:
    AllocatorView() noexcept = default;
    AllocatorView(std::nullptr_t) noexcept {}
    template <class A>
    AllocatorView(const detail::Ref<A>& allocator) noexcept : p_(allocator.get()) {}
    template <class A>
    AllocatorView(detail::Ref<A>&&) = delete;
    DeviceAllocator* get() const noexcept { return p_; }
    explicit operator bool() const noexcept { return p_ != nullptr; }

private:
    DeviceAllocator* p_ = nullptr;
};

// Makes an allocator of type A, owned by the returned reference (which
// converts to SharedAllocator).
template <class A, class... Args>
detail::Ref<A> make_allocator(Args&&... args) {
    return detail::Ref<A>(new A(moves::forward<Args>(args)...));
}

// The memory type for type_bits and intent: the lowest index with every
// required flag and the most preferred (and fewest avoided) flags; -1 if none.
int find_memory_type(const VkPhysicalDeviceMemoryProperties& properties, std::uint32_t type_bits,
                     const MemoryIntent& intent) noexcept;
// find_memory_type, throwing UsageError naming who asked when there is none.
std::uint32_t choose_memory_type(const VkPhysicalDeviceMemoryProperties& properties, std::uint32_t type_bits,
                                 const MemoryIntent& intent, const char* who);
// Whether a memory type must be mapped (host-visible intent or required flag).
bool intent_needs_mapping(const MemoryIntent& intent) noexcept;

// One vkAllocateMemory per resource: the baseline.
class DedicatedAllocator final : public DeviceAllocator {
public:
    AllocationInfo allocate(DeviceView device, const AllocationRequest& request) override;
    void free(DeviceView device, const AllocationInfo& allocation) override;
    AllocatorStatistics statistics(DeviceView device) const override;

private:
    mutable Mutex mutex_;
    AllocatorStatistics stats_;
    std::uint32_t memory_objects_ = 0;
};

// Every member is optional. Copied by the PoolAllocator's constructor.
struct PoolAllocatorCreateInfo {
    // Each kind of block (see PoolAllocator) starts with one block of
    // min_block_size; a new block is min_block_size doubled while it holds
    // less than twice the request that needs it or an eighth of the bytes of
    // that kind already reserved, up to max_block_size (both capped at an
    // eighth of small heaps); never less than the request. A small first
    // block keeps start-up cheap (allocating and mapping a 64 MiB one took
    // about 20 ms on NVIDIA); growing by an eighth keeps the part-used last
    // block a small share of a large pool. Defaults 1 MiB and 256 MiB;
    // min_block_size non-zero and at most max_block_size.
    VkDeviceSize min_block_size = VkDeviceSize{1} << 20;
    VkDeviceSize max_block_size = VkDeviceSize{256} << 20;
    // Requests larger than this get their own VkDeviceMemory; 0: max_block_size / 2 (as VMA).
    VkDeviceSize dedicated_threshold = 0;
    // Empty blocks kept per kind of block (and shard) for reuse; one more
    // empty block releases the smallest. Default 2.
    std::uint32_t spare_blocks = 2;
    // Independent parts (each with its own lock, blocks and spare block) that
    // threads allocating at once spread over, so that they do not queue on
    // one lock. 0: one per hardware thread (at most max_pool_shards) under
    // the multi-thread policy, so that each thread has a home of its own;
    // 1: one lock for everything (the least memory reserved). At most
    // max_pool_shards. The single-thread policy always has one.
    std::uint32_t shards = 0;
};

inline constexpr std::uint32_t max_pool_shards = 64;

// Sub-allocates from large blocks per memory type with TLSF (constant-time
// good fit, freed neighbours merged); host-visible blocks stay mapped, and
// hold either upload ranges (host-written) or gpu_only and readback ones
// (GPU-written) or custom ones, never two of these, so that a capture tool
// that copies host-written pages to the device never overwrites GPU writes;
// empty blocks are released keeping at most spare_blocks per kind of block
// (memory type and the classes above) and shard; its own VkDeviceMemory count stays within maxMemoryAllocationCount.
// The device's default allocator. Serves one device at a time; used directly
// (not through Allocation), call release() before that device goes.
//
// Under the multi-thread policy it is split into shards (see
// PoolAllocatorCreateInfo::shards). Each thread has a home shard; allocate()
// takes the first free lock starting there, waiting on the home shard only
// when all are held, and free() goes back to the shard that made the range,
// from any thread. Shards share no blocks, so the memory trade-off is: with
// threads allocating at once, up to shard count x block size may be
// reserved per memory type (a partly used block and the spares in each shard)
// where one shard would reserve one block's worth.
class PoolAllocator final : public DeviceAllocator {
public:
    explicit PoolAllocator(const PoolAllocatorCreateInfo& info = {});
    ~PoolAllocator() override;
    PoolAllocator(const PoolAllocator&) = delete;
    PoolAllocator& operator=(const PoolAllocator&) = delete;

    AllocationInfo allocate(DeviceView device, const AllocationRequest& request) override;
    void free(DeviceView device, const AllocationInfo& allocation) override;
    void release(DeviceView device) noexcept override;
    AllocatorStatistics statistics(DeviceView device) const override;
    // The number of shards in use (PoolAllocatorCreateInfo::shards resolved).
    std::uint32_t shard_count() const noexcept;

    struct Impl;

private:
    Impl* impl_;  // owned; defined in pool_allocator.cpp
};

// Adds VK_EXT_memory_budget's budget and usage (or the heap sizes) to stats.
void fill_budget(DeviceView device, AllocatorStatistics& stats) noexcept;

namespace detail {

// A flush/invalidate range in VkDeviceMemory coordinates.
struct MemoryRange {
    VkDeviceSize offset = 0;
    VkDeviceSize size = 0;
    friend bool operator==(const MemoryRange&, const MemoryRange&) = default;
};

// The range to flush or invalidate for bytes [offset, offset + size) of an
// allocation (size VK_WHOLE_SIZE: to its end) at allocation_offset with
// allocation_size bytes inside a VkDeviceMemory of memory_size bytes: rounded
// out to atom (nonCoherentAtomSize), its end clamped to the allocation's end
// rounded up to atom and to the memory's end. Vulkan's rule holds for the
// result: offset is a multiple of atom, size is one or reaches the memory's
// end. The caller has checked that the bytes lie in the allocation.
constexpr MemoryRange mapped_range(VkDeviceSize allocation_offset, VkDeviceSize allocation_size,
                                   VkDeviceSize memory_size, VkDeviceSize atom, VkDeviceSize offset,
                                   VkDeviceSize size) noexcept {
    const VkDeviceSize begin = allocation_offset + offset;
    const VkDeviceSize end = size == VK_WHOLE_SIZE ? allocation_offset + allocation_size : begin + size;
    if (end <= begin) return {begin - begin % atom, 0};
    const VkDeviceSize first = begin - begin % atom;
    const VkDeviceSize allocation_end = allocation_offset + allocation_size;
    VkDeviceSize limit = allocation_end + (atom - allocation_end % atom) % atom;
    if (limit > memory_size) limit = memory_size;
    VkDeviceSize last = end + (atom - end % atom) % atom;
    if (last > limit) last = limit;
    return {first, last - first};
}

class AllocationState final : public RefCounted {
public:
    DeviceLink device;
    AllocationInfo info;
    DeviceAllocator* allocator = nullptr;
    VkDeviceSize atom = 1;
    bool coherent = true;

    void flush(VkDeviceSize offset, VkDeviceSize size) const;
    void invalidate(VkDeviceSize offset, VkDeviceSize size) const;

private:
    void on_last_release() noexcept override;
};

[[noreturn]] void throw_not_host_visible(const char* who);
[[noreturn]] void throw_not_host_coherent(const char* who);
[[noreturn]] void throw_out_of_range(const char* who, VkDeviceSize offset, std::size_t count, std::size_t element,
                                     VkDeviceSize size);

// Checks that count elements of element bytes at offset fit in size bytes,
// without overflowing.
inline void check_mapped_range(const char* who, VkDeviceSize offset, std::size_t count, std::size_t element,
                               VkDeviceSize size) {
    if (element != 0 && count > ~VkDeviceSize(0) / element) [[unlikely]] {
        throw_out_of_range(who, offset, count, element, size);
    }
    const VkDeviceSize bytes = VkDeviceSize(count) * element;
    if (offset > size || bytes > size - offset) [[unlikely]]
        throw_out_of_range(who, offset, count, element, size);
}

// The one mapped write, for Allocation and WriteOnlyView: the range check
// (with VKRC_RUNTIME_CHECKS), the copy, and a flush on non-coherent memory.
// The caller passes the mapping's fields it already holds, so the view's
// copies are used without a pointer chase.
template <class T>
inline void write_mapped(const char* who, const AllocationState* s, std::byte* mapped, VkDeviceSize size, bool coherent,
                         VkDeviceSize offset, const T* data, std::size_t count) {
    // The compilers' built-in trait: <type_traits> is parsed by every user of vkrc.
    static_assert(__is_trivially_copyable(T), "mapped writes copy bytes");
#if VKRC_RUNTIME_CHECKS
    check_mapped_range(who, offset, count, sizeof(T), size);
#else
    (void)who;
    (void)size;
#endif
    if (count == 0) return;
    std::memcpy(mapped + offset, data, count * sizeof(T));
    if (!coherent) [[unlikely]]
        s->flush(offset, count * sizeof(T));
}

// The write overloads Allocation and WriteOnlyView share: each is one call
// of Derived's write(offset, data, count).
template <class Derived>
class MappedWrites {
public:
    // Any contiguous range: a std::span, std::vector, std::array, vkrc::Span or List.
    template <class Range>
    requires requires(const Range& r) { r.size(); }
    void write(VkDeviceSize offset, const Range& data) const {
        static_cast<const Derived&>(*this).write(offset, data.data(), data.size());
    }
    template <class T>
    void write_value(VkDeviceSize offset, const T& value) const {
        static_cast<const Derived&>(*this).write(offset, &value, 1);
    }
};

}  // namespace detail

// Writes to host-coherent upload memory as plain copies. Reading
// write-combined memory is slow, so this view has no read; coherent memory
// needs no flush, so a write is the memcpy alone (with VKRC_RUNTIME_CHECKS, a
// range check before it). It holds copies of the mapping's address and size
// (fixed for the allocation's life), so a view kept next to the other
// per-frame data writes with no pointer chase through the Allocation. Use it
// while its Allocation lives.
class WriteOnlyView : public detail::MappedWrites<WriteOnlyView> {
public:
    // An empty view (size 0), to be assigned from Allocation::write_only().
    WriteOnlyView() noexcept = default;
    using MappedWrites::write;
    template <class T>
    void write(VkDeviceSize offset, const T* data, std::size_t count) const {
        // Coherent: write_mapped's flush branch folds away.
        detail::write_mapped("vkrc::WriteOnlyView::write", nullptr, mapped_, size_, true, offset, data, count);
    }
    VkDeviceSize size() const noexcept { return size_; }
    // The bytes [offset, offset + size) as a view of their own (a ring's
    // slice): writes to it take offsets from its start. UsageError (with
    // VKRC_RUNTIME_CHECKS) when the range is not inside this view.
    WriteOnlyView slice(VkDeviceSize offset, VkDeviceSize size) const {
#if VKRC_RUNTIME_CHECKS
        detail::check_mapped_range("vkrc::WriteOnlyView::slice", offset, size, 1, size_);
#endif
        WriteOnlyView v;
        v.mapped_ = mapped_ + offset;
        v.size_ = size;
        return v;
    }

private:
    friend class Allocation;
    explicit WriteOnlyView(const detail::AllocationState* s) noexcept : mapped_(s->info.mapped), size_(s->info.size) {}
    std::byte* mapped_ = nullptr;
    VkDeviceSize size_ = 0;
};

// A range of device memory owned by its handles; keeps its Device alive and
// returns itself to its allocator once the last owner is gone and the GPU
// work submitted before then has completed.
class Allocation : public Handle<detail::AllocationState>, public detail::MappedWrites<Allocation> {
public:
    // Allocates for request from allocator (null: the device's default).
    static Allocation create(const Device& device, const AllocationRequest& request, AllocatorView allocator = {});

    const AllocationInfo& info() const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_STATE("vkrc::Allocation::info");
        return state_->info;
    }
    VkDeviceMemory memory() const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_STATE("vkrc::Allocation::memory");
        return state_->info.memory;
    }
    VkDeviceSize offset() const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_STATE("vkrc::Allocation::offset");
        return state_->info.offset;
    }
    VkDeviceSize size() const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_STATE("vkrc::Allocation::size");
        return state_->info.size;
    }
    std::uint32_t memory_type() const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_STATE("vkrc::Allocation::memory_type");
        return state_->info.memory_type;
    }
    bool host_visible() const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_STATE("vkrc::Allocation::host_visible");
        return state_->info.mapped != nullptr;
    }
    bool host_coherent() const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_STATE("vkrc::Allocation::host_coherent");
        return state_->coherent;
    }
    // Host address of the first byte; null when not host-visible.
    std::byte* mapped() const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_STATE("vkrc::Allocation::mapped");
        return state_->info.mapped;
    }
    DeviceAllocator& allocator() const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_STATE("vkrc::Allocation::allocator");
        return *state_->allocator;
    }

    // Copies count elements to offset (bytes) and flushes them on non-coherent
    // memory. Any alignment of offset is fine. Throws UsageError when the
    // memory is not host-visible and (with VKRC_RUNTIME_CHECKS) when the bytes
    // do not fit or count * sizeof(T) overflows.
    using MappedWrites::write;
    template <class T>
    void write(VkDeviceSize offset, const T* data, std::size_t count) const {
        VKRC_REQUIRE_STATE("vkrc::Allocation::write");
        auto& s = *state_;
        if (!s.info.mapped) [[unlikely]]
            detail::throw_not_host_visible("vkrc::Allocation::write");
        detail::write_mapped("vkrc::Allocation::write", &s, s.info.mapped, s.info.size, s.coherent, offset, data,
                             count);
    }
    // Invalidates the bytes on non-coherent memory, then copies them out.
    template <class T>
    void read(VkDeviceSize offset, T* out, std::size_t count) const {
        static_assert(__is_trivially_copyable(T), "mapped reads copy bytes");  // see write_mapped
        VKRC_REQUIRE_STATE("vkrc::Allocation::read");
        auto& s = *state_;
        if (!s.info.mapped) [[unlikely]]
            detail::throw_not_host_visible("vkrc::Allocation::read");
#if VKRC_RUNTIME_CHECKS
        detail::check_mapped_range("vkrc::Allocation::read", offset, count, sizeof(T), s.info.size);
#endif
        if (count == 0) return;
        if (!s.coherent) [[unlikely]]
            s.invalidate(offset, count * sizeof(T));
        std::memcpy(out, s.info.mapped + offset, count * sizeof(T));
    }
    // Into any contiguous range of writable elements (a std::span, std::vector, ...).
    template <class Range>
    requires requires(Range& r) { r.size(); }
    void read(VkDeviceSize offset, Range&& out) const { read(offset, out.data(), out.size()); }
    template <class T>
    T read_value(VkDeviceSize offset) const {
        T value;
        read(offset, &value, 1);
        return value;
    }
    // For host-coherent upload memory: a view whose writes are plain copies.
    // UsageError on memory that is not host-visible or not host-coherent
    // (request VK_MEMORY_PROPERTY_HOST_COHERENT_BIT in MemoryIntent's
    // required_flags, or use write(), which flushes).
    WriteOnlyView write_only() const {
        if (!state_->info.mapped) detail::throw_not_host_visible("vkrc::Allocation::write_only");
        if (!state_->coherent) detail::throw_not_host_coherent("vkrc::Allocation::write_only");
        return WriteOnlyView(state_.get());
    }

    // For writes through mapped(): size VK_WHOLE_SIZE means to the end.
    // Both do nothing on coherent memory.
    void flush(VkDeviceSize offset = 0, VkDeviceSize size = VK_WHOLE_SIZE) const;
    void invalidate(VkDeviceSize offset = 0, VkDeviceSize size = VK_WHOLE_SIZE) const;

private:
    using Handle::Handle;
    friend class Buffer;
    friend class Image;
};

// The device's default allocator (a PoolAllocator, made on first use).
DeviceAllocator& default_allocator(const Device& device);
// Statistics of the device's default allocator, with the budget.
AllocatorStatistics memory_statistics(const Device& device);

VKRC_END_NAMESPACE
