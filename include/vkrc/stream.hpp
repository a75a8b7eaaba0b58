// Streaming: uploads and downloads through a persistently mapped staging
// ring on a transfer queue, with tickets on that queue's timeline instead of
// CPU waits; and a per-frame ring for transient data (uniforms, dynamic
// vertices) that recycles its frames through a queue's timeline.
#pragma once

#include "vkrc/descriptor.hpp"
#include "vkrc/detail/fifo.hpp"
#include "vkrc/submit.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
class UploaderState;
class FrameRingState;
// What stream.cpp reaches inside Downloads and Uploaders.
struct StreamAccess;
}  // namespace detail

// The end of an Uploader's batch: the value its queue's timeline semaphore
// reaches when the batch's copies are done, and the ownership acquires the
// consumer must record when the copies ran on another queue family. A later
// submission that uses the data waits on wait() and, on another family,
// records record_acquire() first in a command buffer of that submission.
struct Ticket {
    // Empty for a default ticket (nothing to wait for).
    Queue queue{};
    std::uint64_t value = 0;
    // The acquire halves of the batch's ownership transfers (empty when the
    // batch's family is the consumer's).
    List<VkBufferMemoryBarrier2> buffer_acquires{};
    List<VkImageMemoryBarrier2> image_acquires{};

    explicit operator bool() const noexcept { return static_cast<bool>(queue); }
    // For SubmitBatch::waits: the consumer's stages wait for the copies
    // (all commands when the ticket carries acquires, which must follow the wait).
    SemaphoreSubmit wait(VkPipelineStageFlags2 stages = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT) const;
    // Records the acquire barriers into cmd (of the consumer's family) when
    // there are any; before the commands that use the data, in a submission
    // that waits on wait(). Nothing is recorded for the same family.
    void record_acquire(const CommandBuffer& cmd) const;
    // Whether the batch has completed (reads the timeline; never blocks).
    bool done() const;
    // Blocks until the batch has completed (the blocking upload_* helpers).
    void wait_on_host() const;
};

namespace detail {
// The submission number of one Uploader batch, shared with its downloads:
// 0 until the batch is submitted.
class BatchValue final : public RefCounted {
public:
    PolicyAtomic<std::uint64_t> value{0};
};
}  // namespace detail

// A download in flight: its bytes are in readback memory once the batch
// that recorded it has been submitted and has completed.
class Download {
public:
    Download() noexcept = default;
    // The batch's ticket; empty until the Uploader submitted the batch.
    Ticket ticket() const;
    // Waits for the batch (at once when done), then copies the bytes out.
    // UsageError when the batch has not been submitted.
    List<std::byte> read() const;
    VkDeviceSize size() const noexcept { return size_; }

private:
    friend struct detail::StreamAccess;
    Queue queue_;
    detail::Ref<detail::BatchValue> batch_;
    Buffer readback_;
    VkDeviceSize size_ = 0;
};

// Every member is optional.
struct ImageUploadInfo {
    // The image's layout before the upload; UNDEFINED (the default) discards its contents.
    VkImageLayout old_layout = VK_IMAGE_LAYOUT_UNDEFINED;
    // The layout the image is left in, for the work that reads it next (default shader read-only).
    VkImageLayout new_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    // The levels uploaded, from level 0 (default all). Fewer, e.g. level 0
    // alone for generate_mipmaps to fill the rest on the GPU: the data then
    // holds just those levels, and the others are left in new_layout with
    // undefined contents. Must be 1 to the image's mip_levels.
    std::uint32_t level_count = VK_REMAINING_MIP_LEVELS;
};

// Bytes upload_image expects: every mip level of every array layer, tightly
// packed (block-compressed levels in whole blocks, rounded up), level by level and within a level layer by layer (level 0 layer 0,
// level 0 layer 1, ..., level 1 layer 0, ...). With level_count, only the
// first level_count levels (ImageUploadInfo::level_count); UsageError when
// it is 0 or more than the image has.
VkDeviceSize image_data_size(const Image& image, std::uint32_t level_count = VK_REMAINING_MIP_LEVELS);

// Every member but queue is optional.
struct UploaderCreateInfo {
    // Required: the queue the copies run on, usually
    // device.queue_for(QueueRole::transfer).queue. The Uploader keeps it alive.
    Queue queue{};
    // The queue family that uses the uploaded data; when it differs from
    // queue's, every upload is an ownership transfer (release recorded here,
    // acquire in the Ticket). Default: the family of the device's graphics queue.
    std::uint32_t consumer_family = VK_QUEUE_FAMILY_IGNORED;
    // Bytes of the staging ring (default 64 MiB). Each upload must fit in it.
    VkDeviceSize staging_size = VkDeviceSize(64) << 20;
};

// Records uploads into a batch on its queue and submits the batch without
// waiting. An upload copies the data into the staging ring at once (the
// caller's span need not outlive the call) and records the copy; submit()
// sends the batch and returns its Ticket. Ring space is reused once the
// batch that used it has completed; when the ring is full, an upload waits
// for the oldest batch only (submitting the open batch first when it is the
// one in the way). One thread at a time: under the multi-thread policy the
// Uploader's lock serialises its calls.
//
// Destinations must not be in use by the GPU when the batch runs: give
// submit() the waits that say so (e.g. a graphics ticket), or upload into
// fresh resources. The copies of one batch have no barrier between them (one
// per batch keeps a stream of uploads cheap), so they must not overlap: two
// uploads into the same bytes, or a download of bytes the batch uploads, go
// in separate batches (submit() between them). Downloads read resources whose queue family ownership
// is the Uploader's queue's (or that were never used on another family).
class Uploader : public Handle<detail::UploaderState> {
public:
    static Uploader create(const UploaderCreateInfo& info);

    const Queue& queue() const VKRC_UNCHECKED_NOEXCEPT;
    VkDeviceSize staging_size() const VKRC_UNCHECKED_NOEXCEPT;

    // As vkrc::upload_buffer, into the open batch.
    void upload_buffer(const Buffer& buffer, VkDeviceSize offset, Span<const std::byte> data) const;
    // As vkrc::upload_image, into the open batch: every level and layer,
    // block-compressed formats in whole blocks.
    void upload_image(const Image& image, Span<const std::byte> data, const ImageUploadInfo& info = {}) const;
    // Records a copy of size bytes at offset out of buffer (needs
    // VK_BUFFER_USAGE_TRANSFER_SRC_BIT) into the open batch; read() it after submit().
    Download download_buffer(const Buffer& buffer, VkDeviceSize offset, VkDeviceSize size) const;
    // As vkrc::download_image, into the open batch.
    Download download_image(const Image& image, VkImageLayout layout, std::uint32_t mip_level = 0,
                            std::uint32_t array_layer = 0) const;

    // Submits the open batch after the given waits and returns its ticket
    // (signalled on the queue's timeline). With nothing recorded, returns the
    // ticket of the last batch (an empty one if none).
    Ticket submit(Span<const SemaphoreSubmit> waits = {}) const;

private:
    friend struct detail::StreamAccess;
    using Handle::Handle;
};

// Every member but queue is optional.
struct FrameRingCreateInfo {
    // Required: the queue that runs the frames' work; a frame's block is
    // reused once that queue's timeline shows the frame done. Kept alive.
    Queue queue{};
    // Bytes of each frame's block (default 1 MiB).
    VkDeviceSize frame_size = VkDeviceSize(1) << 20;
    // Blocks, one per frame in flight (default 2).
    std::uint32_t frames_in_flight = 2;
    // The buffer's usage (default uniform, storage, vertex and index).
    VkBufferUsageFlags usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                               VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_INDEX_BUFFER_BIT;
};

// A slice of a FrameRing's buffer for this frame.
struct FrameAllocation {
    VkBuffer buffer = VK_NULL_HANDLE;
    // From the start of the ring's buffer: a vertex buffer offset, or the
    // dynamic offset of a descriptor written by write_dynamic_buffer.
    VkDeviceSize offset = 0;
    // The slice's bytes, write-only (offsets from the slice's start).
    WriteOnlyView view{};
    std::uint32_t dynamic_offset() const noexcept { return static_cast<std::uint32_t>(offset); }
};

// Transient per-frame data in one persistently mapped, host-coherent buffer
// split into a block per frame in flight. allocate() bumps an offset in the
// current block (no lock, no call); end_frame() after the frame's submit
// notes the queue's submission number; begin_frame() moves to the next block,
// waiting first (on the queue's timeline, never a fence) only when the GPU
// has not finished the frame that last used it. One thread at a time.
class FrameRing : public Handle<detail::FrameRingState> {
public:
    static FrameRing create(const FrameRingCreateInfo& info);

    const Buffer& buffer() const VKRC_UNCHECKED_NOEXCEPT;
    VkDeviceSize frame_size() const VKRC_UNCHECKED_NOEXCEPT;
    // The block the frame writes into (0 .. frames_in_flight - 1).
    std::uint32_t frame_index() const VKRC_UNCHECKED_NOEXCEPT;

    // Moves to the next block, waiting for the GPU to finish with it.
    void begin_frame() const;
    // After the frame's last submit on the ring's queue: the block is free
    // once the work submitted so far has completed.
    void end_frame() const;
    // size bytes at a multiple of alignment (0: the device's
    // minUniformBufferOffsetAlignment) in the current block; UsageError when
    // the block has no room left or outside begin_frame/end_frame.
    FrameAllocation allocate(VkDeviceSize size, VkDeviceSize alignment = 0) const;

private:
    using Handle::Handle;
};

namespace detail {

// The staging ring's bookkeeping: regions in use, oldest first, each
// tagged with the submission number of its batch (0: the open batch).
class StagingRing {
public:
    explicit StagingRing(VkDeviceSize capacity = 0) noexcept : capacity_(capacity) {}
    // The offset of size bytes at a multiple of alignment, or false when
    // they do not fit before the oldest region in use.
    bool try_allocate(VkDeviceSize size, VkDeviceSize alignment, VkDeviceSize& offset);
    // The open batch's regions belong to submission number value.
    void tag_open(std::uint64_t value) noexcept;
    // Frees the regions of batches up to completed.
    void retire(std::uint64_t completed) noexcept;
    // The oldest region's number (0: the open batch's; UINT64_MAX: none).
    std::uint64_t oldest() const noexcept { return regions_.empty() ? UINT64_MAX : regions_.front().value; }

private:
    struct Region {
        VkDeviceSize begin = 0, end = 0;
        std::uint64_t value = 0;
    };
    VkDeviceSize capacity_;
    Fifo<Region> regions_;
};

class UploaderState final : public RefCounted {
public:
    Queue queue;
    std::uint32_t consumer_family = 0;
    Buffer staging;
    WriteOnlyView staging_view;
    StagingRing ring;
    CommandPool pool;
    // Command buffers of submitted batches, each with its submission number,
    // oldest first: the front is the first to complete.
    struct Recorded {
        CommandBuffer cmd;
        std::uint64_t value = 0;
    };
    Fifo<Recorded> recorded;
    // The open batch: its command buffer (empty when none), the barriers
    // recorded at its end, the acquires its ticket carries, its value.
    CommandBuffer open;
    List<VkBufferMemoryBarrier2> buffer_releases;
    List<VkImageMemoryBarrier2> image_ends;
    Ticket pending;
    bool host_reads = false;
    // The blocking helpers' batches end with the copies made visible: their
    // callers' later submissions need not wait on the batch's semaphore.
    bool visible_at_end = false;
    Ref<BatchValue> batch;  // made by the open batch's first download (empty: none yet)
    Ticket last;
    mutable Mutex mutex;
};

class FrameRingState final : public RefCounted {
public:
    Queue queue;
    Buffer buffer;
    WriteOnlyView view;
    VkDeviceSize frame_size = 0;
    VkDeviceSize min_alignment = 1;
    List<std::uint64_t> frame_values;  // per block: the submission number it waits for
    std::uint32_t index = 0;
    VkDeviceSize head = 0;
    bool open = false;
};

}  // namespace detail

// Writes the ring's buffer into binding of set as a dynamic uniform (or,
// with storage, dynamic storage) buffer of range bytes at offset 0; bind the
// set with FrameAllocation::dynamic_offset() for each draw's slice.
void write_dynamic_buffer(const DescriptorSet& set, std::uint32_t binding, const FrameRing& ring, VkDeviceSize range,
                          bool storage = false);

VKRC_END_NAMESPACE
