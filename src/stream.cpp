#include "vkrc/stream.hpp"

#include "staging.hpp"

#include <algorithm>
#include <numeric>
#include <type_traits>

VKRC_BEGIN_NAMESPACE

// ---------------------------------------------------------------- Ticket

SemaphoreSubmit Ticket::wait(VkPipelineStageFlags2 stages) const {
    detail::Caller{"vkrc::Ticket::wait"}.require(static_cast<bool>(queue), "the ticket is empty");
    SemaphoreSubmit s;
    s.semaphore = queue.timeline_semaphore();
    s.value = value;
    // The acquire barriers (destination: all commands) come after the wait
    // only when the wait covers their stages.
    const bool acquires = !buffer_acquires.empty() || !image_acquires.empty();
    s.stage_mask = acquires ? VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT : stages;
    return s;
}

void Ticket::record_acquire(const CommandBuffer& cmd) const {
    if (buffer_acquires.empty() && image_acquires.empty()) return;
    cmd.pipeline_barrier({}, {buffer_acquires.data(), buffer_acquires.size()},
                         {image_acquires.data(), image_acquires.size()});
}

namespace {
// Waits for value on queue, then runs the deferred destructions it allowed.
void await(const Queue& queue, std::uint64_t value) {
    detail::await(queue, value);
    queue.device().collect_garbage();
}
}  // namespace

bool Ticket::done() const {
    if (!queue || detail::completed(queue) >= value) return true;
    return detail::read_completed(queue) >= value || queue.device().lost();
}

void Ticket::wait_on_host() const {
    if (queue) await(queue, value);
}

// ---------------------------------------------------------------- Download

Ticket Download::ticket() const {
    if (!batch_ || batch_->value.load() == 0) return {};
    return Ticket{queue_, batch_->value.load(), {}, {}};
}

List<std::byte> Download::read() const {
    const Ticket t = ticket();
    detail::Caller{"vkrc::Download::read"}.require(static_cast<bool>(t),
                                                   "the download is empty or its batch was not submitted");
    t.wait_on_host();
    List<std::byte> out(size_);
    readback_.allocation().read(0, out);
    return out;
}

// ---------------------------------------------------------------- StagingRing

namespace detail {

bool StagingRing::try_allocate(VkDeviceSize size, VkDeviceSize alignment, VkDeviceSize& offset) {
    if (size > capacity_) return false;
    VkDeviceSize place = 0;
    if (!regions_.empty()) {
        const VkDeviceSize head = regions_.back().end, tail = regions_.front().begin;
        const VkDeviceSize aligned = (head + alignment - 1) / alignment * alignment;
        if (head > tail && aligned + size <= capacity_) {
            place = aligned;
        } else if (head > tail && size <= tail) {
            place = 0;  // wraps; the bytes after head stay unused this round
        } else if (head < tail && aligned + size <= tail) {
            place = aligned;
        } else {
            return false;
        }
    }
    if (!regions_.empty() && regions_.back().value == 0 && regions_.back().end <= place) {
        regions_.back().end = place + size;  // the open batch grows
    } else {
        regions_.push_back(Region{place, place + size, 0});
    }
    offset = place;
    return true;
}

void StagingRing::tag_open(std::uint64_t value) noexcept {
    for (std::size_t i = regions_.size(); i-- > 0 && regions_[i].value == 0;) regions_[i].value = value;
}

void StagingRing::retire(std::uint64_t completed) noexcept {
    while (!regions_.empty() && regions_.front().value != 0 && regions_.front().value <= completed)
        regions_.pop_front();
}

}  // namespace detail

// ---------------------------------------------------------------- Checks

namespace detail {
namespace {

// The buffer or image exists, belongs to the Uploader's device and has the
// transfer usage (usage_name) it needs.
template <class Resource>
void check_resource(const UploaderState& s, const Resource& resource, std::uint32_t usage, const char* usage_name,
                    const Caller& caller) {
    constexpr bool buffer = std::is_same_v<Resource, Buffer>;
    caller.require(static_cast<bool>(resource), buffer ? "the Buffer is empty" : "the Image is empty");
    caller.require(s.queue.device() == resource.device(), "the queue belongs to another device");
    caller.require((resource.usage() & usage) != 0, buffer ? "the buffer lacks " : "the image lacks ", usage_name);
}

// size bytes at offset lie in the buffer.
void check_buffer_range(const Buffer& buffer, VkDeviceSize offset, VkDeviceSize size, const Caller& caller) {
    caller.require(offset <= buffer.size() && size <= buffer.size() - offset, size, " bytes at offset ", offset,
                   " do not fit in the ", buffer.size(), "-byte buffer");
}

// a * b; refused when it does not fit in 64 bits.
VkDeviceSize checked_mul(VkDeviceSize a, VkDeviceSize b, const Caller& caller) {
    VkDeviceSize r = 0;
    caller.require(!__builtin_mul_overflow(a, b, &r), "the image's size in bytes overflows 64 bits");
    return r;
}

// The image's copy unit; refused for formats the staging code does not handle.
FormatBlock checked_block(const Image& image, const Caller& caller) {
    const FormatBlock block = format_block(image.format());
    caller.require(block.bytes != 0, "format ", image.format(),
                   " is neither an uncompressed colour format nor block-compressed");
    caller.require(image.samples() == VK_SAMPLE_COUNT_1_BIT, "the image is multisampled");
    return block;
}

// The number of levels an upload of level_count (VK_REMAINING_MIP_LEVELS:
// all) covers; refused when it is 0 or more than the image has.
std::uint32_t uploaded_levels(const Image& image, std::uint32_t level_count, const Caller& caller) {
    if (level_count == VK_REMAINING_MIP_LEVELS) return image.mip_levels();
    caller.require(level_count != 0 && level_count <= image.mip_levels(), "level_count ", level_count,
                   " is not 1 to the image's ", image.mip_levels(), " levels");
    return level_count;
}

// Bytes of one array layer of a mip level, in whole blocks.
VkDeviceSize level_size(const Image& image, std::uint32_t level, const FormatBlock& block, const Caller& caller) {
    const VkExtent3D e = image.extent(level);
    const VkDeviceSize columns = (VkDeviceSize(e.width) + block.width - 1) / block.width;
    const VkDeviceSize rows = (VkDeviceSize(e.height) + block.height - 1) / block.height;
    return checked_mul(checked_mul(checked_mul(columns, rows, caller), e.depth, caller), block.bytes, caller);
}

// image_data_size's work.
VkDeviceSize image_bytes(const Image& image, std::uint32_t level_count, const Caller& caller) {
    const FormatBlock block = checked_block(image, caller);
    const std::uint32_t levels = uploaded_levels(image, level_count, caller);
    VkDeviceSize total = 0;
    for (std::uint32_t level = 0; level < levels; ++level) {
        const VkDeviceSize level_bytes =
            checked_mul(level_size(image, level, block, caller), image.array_layers(), caller);
        caller.require(total + level_bytes >= total, "the image's size in bytes overflows 64 bits");
        total += level_bytes;
    }
    return total;
}

// upload_image's checks of data and info against the image.
void check_image_upload(const Image& image, Span<const std::byte> data, const ImageUploadInfo& info,
                        const Caller& caller) {
    const VkDeviceSize expected = image_bytes(image, info.level_count, caller);
    if (data.size() != expected) {
        if (info.level_count == VK_REMAINING_MIP_LEVELS)
            caller.refuse(data.size(), " bytes given; every level and layer of the image take ", expected);
        caller.refuse(data.size(), " bytes given; ", info.level_count, " levels and layer of the image take ",
                      expected);
    }
    caller.require(info.new_layout != VK_IMAGE_LAYOUT_UNDEFINED && info.new_layout != VK_IMAGE_LAYOUT_PREINITIALIZED,
                   "new_layout must be a layout an image can be transitioned to");
}

// download_image's checks of the level, layer and layout.
void check_image_download(const Image& image, VkImageLayout layout, std::uint32_t mip_level, std::uint32_t array_layer,
                          const Caller& caller) {
    caller.require(mip_level < image.mip_levels() && array_layer < image.array_layers(), "level ", mip_level, " layer ",
                   array_layer, " is not in the image");
    caller.require(layout != VK_IMAGE_LAYOUT_UNDEFINED, "the image's layout is UNDEFINED");
}

}  // namespace
}  // namespace detail

VkDeviceSize image_data_size(const Image& image, std::uint32_t level_count) {
    return detail::image_bytes(image, level_count, detail::Caller{"vkrc::image_data_size"});
}

// ---------------------------------------------------------------- Uploader

namespace {

constexpr VkAccessFlags2 memory_rw = VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT;

// The batch's first command: earlier work on the queue finishes writing and
// reading what the copies touch (one barrier per batch, not per copy).
void begin_batch(detail::UploaderState& s) {
    // The oldest batch's command buffer if that batch completed: by the
    // cached value, else by the semaphore's (so that a stream that never
    // fills the ring, and so never reads the semaphore there, still reuses
    // them); else a new one.
    if (!s.recorded.empty() && (s.recorded.front().value <= detail::completed(s.queue) ||
                                s.recorded.front().value <= detail::read_completed(s.queue))) {
        s.open = std::move(s.recorded.front().cmd);
        s.recorded.pop_front();
    } else {
        s.open = s.pool.allocate();
    }
    s.open.begin(VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT);
    const VkMemoryBarrier2 b =
        memory_barrier(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                       VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT);
    s.open.pipeline_barrier({&b, 1}, {}, {});
    s.batch = {};  // made by the batch's first download only
}

// The barriers after the copies recorded so far: ownership releases, or,
// within the family, the images moved to their new layouts, and, with
// visible, the copies made visible to all later commands on the queue.
// Recorded at the batch's end and before a download (which may read what an
// upload of the batch wrote). A streaming batch's end needs no visibility
// barrier: its consumers wait on its semaphore signal, which makes every
// write of the batch visible to them.
void record_ends(detail::UploaderState& s, bool visible) {
    const VkMemoryBarrier2 b = memory_barrier(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                              VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, memory_rw);
    if (!visible && s.buffer_releases.empty() && s.image_ends.empty()) return;
    s.open.pipeline_barrier({&b, visible ? 1u : 0u}, {s.buffer_releases.data(), s.buffer_releases.size()},
                            {s.image_ends.data(), s.image_ends.size()});
    s.buffer_releases.clear();
    s.image_ends.clear();
}

void end_batch(detail::UploaderState& s) {
    record_ends(s, s.visible_at_end);
    if (s.host_reads) {
        const VkMemoryBarrier2 b = memory_barrier(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                                  VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
        s.open.pipeline_barrier({&b, 1}, {}, {});
    }
    s.open.end();
}

// Submits the open batch; under the Uploader's lock.
Ticket submit_batch(detail::UploaderState& s, Span<const SemaphoreSubmit> waits) {
    end_batch(s);
    List<VkSemaphoreSubmitInfo> wait_infos;
    for (const auto& w : waits) wait_infos.push_back(w.info());
    VkCommandBufferSubmitInfo cmd{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
    cmd.commandBuffer = s.open.vk();
    VkSubmitInfo2 info{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    info.waitSemaphoreInfoCount = static_cast<std::uint32_t>(wait_infos.size());
    info.pWaitSemaphoreInfos = wait_infos.data();
    info.commandBufferInfoCount = 1;
    info.pCommandBufferInfos = &cmd;
    CommandBuffer open = std::move(s.open);
    s.open = {};
    s.host_reads = false;
    std::uint64_t value;
    try {
        value = detail::submit_signalled(s.queue, {&info, 1});
    } catch (...) {
        // Nothing of the batch runs (or the device is lost): its ring space
        // is free once the work before it is.
        s.ring.tag_open(detail::last_submitted(s.queue));
        s.pending = {};
        throw;
    }
    detail::close_submitted({&open, 1});
    s.recorded.push_back({std::move(open), value});
    s.ring.tag_open(value);
    if (s.batch) s.batch->value.store(value);
    Ticket ticket = std::move(s.pending);
    ticket.queue = s.queue;
    ticket.value = value;
    s.pending = {};
    s.last = Ticket{s.queue, value, {}, {}};  // its acquires are recorded once, from the returned ticket
    return ticket;
}

// Ring space for size bytes, waiting for the oldest batch while there is
// none (after submitting the open batch when it is the one in the way).
VkDeviceSize reserve(detail::UploaderState& s, VkDeviceSize size, VkDeviceSize alignment,
                     const detail::Caller& caller) {
    caller.require(size <= s.staging.size(), size, " bytes do not fit in the ", s.staging.size(), "-byte staging ring");
    s.ring.retire(detail::completed(s.queue));
    VkDeviceSize offset = 0;
    while (!s.ring.try_allocate(size, alignment, offset)) {
        s.ring.retire(detail::read_completed(s.queue));
        if (s.ring.try_allocate(size, alignment, offset)) break;
        if (s.ring.oldest() == 0) {
            // The batch's acquires go with the next ticket, which covers it.
            Ticket carried = submit_batch(s, {});
            s.pending.buffer_acquires = std::move(carried.buffer_acquires);
            s.pending.image_acquires = std::move(carried.image_acquires);
        }
        await(s.queue, s.ring.oldest());
        s.ring.retire(s.queue.device().lost() ? UINT64_MAX - 1 : detail::completed(s.queue));
    }
    return offset;
}

void open_batch(detail::UploaderState& s) {
    if (!s.open) begin_batch(s);
}

// Where the open batch's submission number will be stored, for its downloads.
detail::Ref<detail::BatchValue> open_batch_value(detail::UploaderState& s) {
    if (!s.batch) s.batch = detail::Ref<detail::BatchValue>(new detail::BatchValue);
    return s.batch;
}

}  // namespace

namespace detail {

// Makes the Uploaders and Downloads, whose constructor and members only
// this file's recording reaches.
struct StreamAccess {
    static Uploader uploader(Ref<UploaderState> state) { return Uploader(std::move(state)); }
    // A readback buffer of size bytes for a download recorded in the open batch.
    static Buffer readback_buffer(UploaderState& s, VkDeviceSize size) {
        BufferCreateInfo info;
        info.size = size;
        info.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
        info.memory.usage = MemoryUsage::readback;
        Buffer readback = Buffer::create(s.queue.device(), info);
        open_batch(s);
        record_ends(s, true);
        s.host_reads = true;
        return readback;
    }
    // The download of size bytes into readback, whose copy the open batch just recorded.
    static Download recorded(UploaderState& s, Buffer readback, VkDeviceSize size) {
        Download d;
        d.queue_ = s.queue;
        d.batch_ = open_batch_value(s);
        d.readback_ = std::move(readback);
        d.size_ = size;
        return d;
    }
};

Uploader create_uploader(const UploaderCreateInfo& info, const Caller& caller) {
    caller.require(static_cast<bool>(info.queue), "the Queue is empty");
    caller.require(info.staging_size != 0, "staging_size is 0");
    const Device& device = info.queue.device();
    Ref<UploaderState> state(new UploaderState);
    auto& s = *state;
    s.queue = info.queue;
    s.consumer_family = info.consumer_family != VK_QUEUE_FAMILY_IGNORED
                            ? info.consumer_family
                            : device.queue_for(QueueRole::graphics).queue.family_index();
    caller.require(s.consumer_family < device.physical_device().queue_families().size(), "consumer_family ",
                   s.consumer_family, " does not exist");
    BufferCreateInfo staging;
    staging.size = info.staging_size;
    staging.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    staging.memory.usage = MemoryUsage::upload;
    staging.memory.required_flags = VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;  // written through a WriteOnlyView
    s.staging = Buffer::create(device, staging);
    s.staging_view = s.staging.allocation().write_only();
    s.ring = StagingRing(info.staging_size);
    s.pool = CommandPool::create(device, {VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT, s.queue.family_index()});
    return StreamAccess::uploader(std::move(state));
}

Uploader one_time_uploader(const Queue& queue, VkDeviceSize size, const Caller& caller) {
    Uploader uploader = create_uploader({.queue = queue, .staging_size = std::max<VkDeviceSize>(size, 1)}, caller);
    auto& s = *uploader.state();
    s.consumer_family = queue.family_index();  // the queue's own: no ownership transfers
    s.visible_at_end = true;
    return uploader;
}

void record_upload(UploaderState& s, const Buffer& buffer, VkDeviceSize offset, Span<const std::byte> data,
                   const Caller& caller) {
    check_resource(s, buffer, VK_BUFFER_USAGE_TRANSFER_DST_BIT, "VK_BUFFER_USAGE_TRANSFER_DST_BIT", caller);
    check_buffer_range(buffer, offset, data.size(), caller);
    if (data.empty()) return;
    LockGuard lock(s.mutex);
    const VkDeviceSize at = reserve(s, data.size(), 4, caller);
    s.staging_view.write(at, data);
    open_batch(s);
    const VkBufferCopy region{at, offset, data.size()};
    s.open.copy_buffer(s.staging.vk(), buffer.vk(), {&region, 1});
    const std::uint32_t family = s.queue.family_index();
    if (s.consumer_family == family) return;
    const BufferOwnershipTransfer transfer{buffer.vk(), family, s.consumer_family, offset, data.size()};
    s.buffer_releases.push_back(transfer.release(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT));
    s.pending.buffer_acquires.push_back(transfer.acquire(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, memory_rw));
}

namespace {

// One region per uploaded mip level (every layer), from offset on in the staging ring.
List<VkBufferImageCopy> level_regions(const Image& image, std::uint32_t levels, VkDeviceSize offset,
                                      const FormatBlock& block, const Caller& caller) {
    List<VkBufferImageCopy> regions;
    for (std::uint32_t level = 0; level < levels; ++level) {
        VkBufferImageCopy r{};
        r.bufferOffset = offset;
        r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, level, 0, image.array_layers()};
        r.imageExtent = image.extent(level);
        regions.push_back(r);
        offset += level_size(image, level, block, caller) * image.array_layers();
    }
    return regions;
}

}  // namespace

void record_upload(UploaderState& s, const Image& image, Span<const std::byte> data, const ImageUploadInfo& info,
                   const Caller& caller) {
    check_resource(s, image, VK_IMAGE_USAGE_TRANSFER_DST_BIT, "VK_IMAGE_USAGE_TRANSFER_DST_BIT", caller);
    check_image_upload(image, data, info, caller);
    const FormatBlock block = checked_block(image, caller);
    LockGuard lock(s.mutex);
    // Buffer offsets of image copies are multiples of the block (and of 4).
    const VkDeviceSize at = reserve(s, data.size(), std::lcm<VkDeviceSize>(block.bytes, 16), caller);
    s.staging_view.write(at, data);
    open_batch(s);
    const VkImageSubresourceRange all{VK_IMAGE_ASPECT_COLOR_BIT, 0, image.mip_levels(), 0, image.array_layers()};
    const auto to_copy = image_barrier(image.vk(), all, info.old_layout, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                       VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                                       VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    s.open.pipeline_barrier({}, {}, {&to_copy, 1});
    const auto regions = level_regions(image, uploaded_levels(image, info.level_count, caller), at, block, caller);
    s.open.copy_buffer_to_image(s.staging.vk(), image.vk(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                {regions.data(), regions.size()});
    const std::uint32_t family = s.queue.family_index();
    if (s.consumer_family == family) {
        s.image_ends.push_back(image_barrier(image.vk(), all, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, info.new_layout,
                                             VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                             VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, memory_rw));
        return;
    }
    const ImageOwnershipTransfer transfer{image.vk(),      all,    VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                          info.new_layout, family, s.consumer_family};
    s.image_ends.push_back(transfer.release(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT));
    s.pending.image_acquires.push_back(transfer.acquire(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, memory_rw));
}

Download record_download(UploaderState& s, const Buffer& buffer, VkDeviceSize offset, VkDeviceSize size,
                         const Caller& caller) {
    check_resource(s, buffer, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, "VK_BUFFER_USAGE_TRANSFER_SRC_BIT", caller);
    check_buffer_range(buffer, offset, size, caller);
    if (size == 0) return {};
    LockGuard lock(s.mutex);
    Buffer readback = StreamAccess::readback_buffer(s, size);
    const VkBufferCopy region{offset, 0, size};
    s.open.copy_buffer(buffer.vk(), readback.vk(), {&region, 1});
    return StreamAccess::recorded(s, std::move(readback), size);
}

Download record_download(UploaderState& s, const Image& image, VkImageLayout layout, std::uint32_t mip_level,
                         std::uint32_t array_layer, const Caller& caller) {
    check_resource(s, image, VK_IMAGE_USAGE_TRANSFER_SRC_BIT, "VK_IMAGE_USAGE_TRANSFER_SRC_BIT", caller);
    check_image_download(image, layout, mip_level, array_layer, caller);
    const VkDeviceSize size = level_size(image, mip_level, checked_block(image, caller), caller);
    LockGuard lock(s.mutex);
    Buffer readback = StreamAccess::readback_buffer(s, size);
    const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, mip_level, 1, array_layer, 1};
    const auto to_copy = image_barrier(image.vk(), range, layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                       VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                                       VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    s.open.pipeline_barrier({}, {}, {&to_copy, 1});
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, mip_level, array_layer, 1};
    region.imageExtent = image.extent(mip_level);
    s.open.copy_image_to_buffer(image.vk(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback.vk(), {&region, 1});
    s.image_ends.push_back(image_barrier(image.vk(), range, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, layout,
                                         VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_NONE,
                                         VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, memory_rw));
    return StreamAccess::recorded(s, std::move(readback), size);
}

}  // namespace detail

Uploader Uploader::create(const UploaderCreateInfo& info) {
    return detail::create_uploader(info, detail::Caller{"vkrc::Uploader::create"});
}

const Queue& Uploader::queue() const VKRC_UNCHECKED_NOEXCEPT { return live("vkrc::Uploader::queue").queue; }

VkDeviceSize Uploader::staging_size() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::Uploader::staging_size").staging.size();
}

void Uploader::upload_buffer(const Buffer& buffer, VkDeviceSize offset, Span<const std::byte> data) const {
    const detail::Caller caller{"vkrc::Uploader::upload_buffer"};
    VKRC_REQUIRE_STATE(caller.name());
    detail::record_upload(*state_, buffer, offset, data, caller);
}

void Uploader::upload_image(const Image& image, Span<const std::byte> data, const ImageUploadInfo& info) const {
    const detail::Caller caller{"vkrc::Uploader::upload_image"};
    VKRC_REQUIRE_STATE(caller.name());
    detail::record_upload(*state_, image, data, info, caller);
}

Download Uploader::download_buffer(const Buffer& buffer, VkDeviceSize offset, VkDeviceSize size) const {
    const detail::Caller caller{"vkrc::Uploader::download_buffer"};
    VKRC_REQUIRE_STATE(caller.name());
    caller.require(size != 0, "size is 0");
    return detail::record_download(*state_, buffer, offset, size, caller);
}

Download Uploader::download_image(const Image& image, VkImageLayout layout, std::uint32_t mip_level,
                                  std::uint32_t array_layer) const {
    const detail::Caller caller{"vkrc::Uploader::download_image"};
    VKRC_REQUIRE_STATE(caller.name());
    return detail::record_download(*state_, image, layout, mip_level, array_layer, caller);
}

Ticket Uploader::submit(Span<const SemaphoreSubmit> waits) const {
    VKRC_REQUIRE_STATE("vkrc::Uploader::submit");
    auto& s = *state_;
    LockGuard lock(s.mutex);
    if (!s.open) return s.last;
    return submit_batch(s, waits);
}

// ---------------------------------------------------------------- FrameRing

FrameRing FrameRing::create(const FrameRingCreateInfo& info) {
    const detail::Caller caller{"vkrc::FrameRing::create"};
    caller.require(static_cast<bool>(info.queue), "the Queue is empty");
    caller.require(info.frame_size != 0 && info.frames_in_flight != 0, "frame_size and frames_in_flight must not be 0");
    const Device& device = info.queue.device();
    const auto& limits = device.physical_device().properties().limits;
    detail::Ref<detail::FrameRingState> state(new detail::FrameRingState);
    auto& s = *state;
    s.queue = info.queue;
    s.min_alignment = std::lcm(limits.minUniformBufferOffsetAlignment, limits.minStorageBufferOffsetAlignment);
    // Blocks start at multiples of the alignment, so slices' offsets are too.
    s.frame_size = (info.frame_size + s.min_alignment - 1) / s.min_alignment * s.min_alignment;
    BufferCreateInfo buffer;
    buffer.size = s.frame_size * info.frames_in_flight;
    buffer.usage = info.usage;
    buffer.memory.usage = MemoryUsage::upload;
    buffer.memory.required_flags = VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;  // written through WriteOnlyViews
    s.buffer = Buffer::create(device, buffer);
    s.view = s.buffer.allocation().write_only();
    s.frame_values = List<std::uint64_t>(info.frames_in_flight);
    s.index = info.frames_in_flight - 1;  // the first begin_frame takes block 0
    return FrameRing(std::move(state));
}

const Buffer& FrameRing::buffer() const VKRC_UNCHECKED_NOEXCEPT { return live("vkrc::FrameRing::buffer").buffer; }

VkDeviceSize FrameRing::frame_size() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::FrameRing::frame_size").frame_size;
}

std::uint32_t FrameRing::frame_index() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::FrameRing::frame_index").index;
}

void FrameRing::begin_frame() const {
    const detail::Caller caller{"vkrc::FrameRing::begin_frame"};
    VKRC_REQUIRE_STATE(caller.name());
    auto& s = *state_;
    caller.require(!s.open, "the frame before was not ended (end_frame)");
    s.index = (s.index + 1) % static_cast<std::uint32_t>(s.frame_values.size());
    const std::uint64_t value = s.frame_values[s.index];
    if (value != 0 && detail::completed(s.queue) < value) await(s.queue, value);
    s.head = 0;
    s.open = true;
}

void FrameRing::end_frame() const {
    const detail::Caller caller{"vkrc::FrameRing::end_frame"};
    VKRC_REQUIRE_STATE(caller.name());
    auto& s = *state_;
    caller.require(s.open, "no frame was begun (begin_frame)");
    s.frame_values[s.index] = detail::covering_value(s.queue);
    s.open = false;
}

FrameAllocation FrameRing::allocate(VkDeviceSize size, VkDeviceSize alignment) const {
    const detail::Caller caller{"vkrc::FrameRing::allocate"};
    VKRC_REQUIRE_STATE(caller.name());
    auto& s = *state_;
    caller.require(s.open, "outside begin_frame / end_frame");
    if (alignment == 0) alignment = s.min_alignment;
    const VkDeviceSize at = (s.head + alignment - 1) / alignment * alignment;
    if (at > s.frame_size || size > s.frame_size - at) {
        caller.refuse(size, " bytes do not fit in the frame's block (", s.frame_size - std::min(at, s.frame_size),
                      " of ", s.frame_size, " bytes left)");
    }
    s.head = at + size;
    const VkDeviceSize offset = VkDeviceSize(s.index) * s.frame_size + at;
    return {s.buffer.vk(), offset, s.view.slice(offset, size)};
}

void write_dynamic_buffer(const DescriptorSet& set, std::uint32_t binding, const FrameRing& ring, VkDeviceSize range,
                          bool storage) {
    detail::Caller{"vkrc::write_dynamic_buffer"}.require(static_cast<bool>(ring), "the FrameRing is empty");
    const VkDescriptorType type =
        storage ? VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC : VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC;
    set.write_buffer(binding, type, ring.buffer(), 0, range);
}

VKRC_END_NAMESPACE
