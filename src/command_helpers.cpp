// Barrier helpers (vkrc/barrier.hpp), generate_mipmaps (vkrc/mipmap.hpp),
// queue labels and the out-of-line error paths of recording methods (kept
// here so that command.cpp stays the pool and command buffer lifetime code).
#include "vkrc/mipmap.hpp"

#include "object_state.hpp"

#include <algorithm>
#include <string>

VKRC_BEGIN_NAMESPACE

namespace detail {
void throw_bad_update_buffer(VkDeviceSize offset, VkDeviceSize size) {
    Caller("vkrc::CommandBuffer::update_buffer")
        .refuse("offset ", offset, " and size ", size, "; both must be multiples of 4 and size in 4..65536");
}
}  // namespace detail

namespace {
// A barrier of the ownership transfer from src_family to dst_family: the
// release and acquire helpers differ only in which half carries the stages.
template <class Barrier>
Barrier between_families(Barrier b, std::uint32_t src_family, std::uint32_t dst_family) noexcept {
    b.srcQueueFamilyIndex = src_family;
    b.dstQueueFamilyIndex = dst_family;
    return b;
}
}  // namespace

VkImageSubresourceRange mip_range(std::uint32_t base_level, std::uint32_t level_count,
                                  VkImageAspectFlags aspect) noexcept {
    return {aspect, base_level, level_count, 0, VK_REMAINING_ARRAY_LAYERS};
}

VkImageSubresourceRange layer_range(std::uint32_t base_layer, std::uint32_t layer_count,
                                    VkImageAspectFlags aspect) noexcept {
    return {aspect, 0, VK_REMAINING_MIP_LEVELS, base_layer, layer_count};
}

VkBufferMemoryBarrier2 buffer_barrier(VkBuffer buffer, VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                                      VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access, VkDeviceSize offset,
                                      VkDeviceSize size) noexcept {
    return {.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2,
            .pNext = nullptr,
            .srcStageMask = src_stage,
            .srcAccessMask = src_access,
            .dstStageMask = dst_stage,
            .dstAccessMask = dst_access,
            .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
            .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
            .buffer = buffer,
            .offset = offset,
            .size = size};
}

VkImageMemoryBarrier2 ImageOwnershipTransfer::release(VkPipelineStageFlags2 src_stage,
                                                      VkAccessFlags2 src_access) const noexcept {
    const auto b = image_barrier(image, range, old_layout, new_layout, src_stage, src_access, VK_PIPELINE_STAGE_2_NONE,
                                 VK_ACCESS_2_NONE);
    return between_families(b, src_family, dst_family);
}

VkImageMemoryBarrier2 ImageOwnershipTransfer::acquire(VkPipelineStageFlags2 dst_stage,
                                                      VkAccessFlags2 dst_access) const noexcept {
    const auto b = image_barrier(image, range, old_layout, new_layout, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE,
                                 dst_stage, dst_access);
    return between_families(b, src_family, dst_family);
}

VkBufferMemoryBarrier2 BufferOwnershipTransfer::release(VkPipelineStageFlags2 src_stage,
                                                        VkAccessFlags2 src_access) const noexcept {
    const auto b =
        buffer_barrier(buffer, src_stage, src_access, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE, offset, size);
    return between_families(b, src_family, dst_family);
}

VkBufferMemoryBarrier2 BufferOwnershipTransfer::acquire(VkPipelineStageFlags2 dst_stage,
                                                        VkAccessFlags2 dst_access) const noexcept {
    const auto b =
        buffer_barrier(buffer, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE, dst_stage, dst_access, offset, size);
    return between_families(b, src_family, dst_family);
}

// generate_mipmaps

namespace {

// The checks Vulkan would otherwise report as undefined behaviour or a device loss.
void check_mipmap_image(const detail::Caller& caller, const CommandBuffer& cmd, const Image& image,
                        const MipmapInfo& info) {
    caller.require_handle(cmd, "the CommandBuffer");
    caller.require_handle(image, "the Image");
    constexpr VkImageUsageFlags transfer = VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    caller.require((image.usage() & transfer) == transfer, "the image lacks TRANSFER_SRC and TRANSFER_DST usage");
    caller.require(image.samples() == VK_SAMPLE_COUNT_1_BIT, "the image is multisampled");
    caller.require(info.base_layout != VK_IMAGE_LAYOUT_UNDEFINED, "base_layout is UNDEFINED: level 0 has no contents");
    caller.require(info.base_layer < image.array_layers() &&
                       (info.layer_count == VK_REMAINING_ARRAY_LAYERS ||
                        (info.layer_count > 0 && info.layer_count <= image.array_layers() - info.base_layer)),
                   "layers out of the image's range");
    const auto& physical = image.device().physical_device();
    const auto& families = physical.queue_families();
    const auto family = cmd.pool().queue_family_index();
    caller.require(family < families.size() && (families[family].queueFlags & VK_QUEUE_GRAPHICS_BIT),
                   "blits need a queue family with graphics");
    VkFormatProperties props{};
    physical.instance().fn().vkGetPhysicalDeviceFormatProperties(physical.vk(), image.format(), &props);
    const auto features = props.optimalTilingFeatures;
    caller.require((features & VK_FORMAT_FEATURE_BLIT_SRC_BIT) && (features & VK_FORMAT_FEATURE_BLIT_DST_BIT),
                   "the format ", image.format(), " cannot be blitted");
    caller.require(info.filter != VK_FILTER_LINEAR || (features & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT),
                   "the format ", image.format(), " cannot be filtered linearly; use VK_FILTER_NEAREST");
}

VkOffset3D end_of(VkExtent3D e) {
    return {static_cast<std::int32_t>(e.width), static_cast<std::int32_t>(e.height),
            static_cast<std::int32_t>(e.depth)};
}

}  // namespace

void generate_mipmaps(const CommandBuffer& cmd, const Image& image, const MipmapInfo& info) {
    const detail::Caller caller{"vkrc::generate_mipmaps"};
    check_mipmap_image(caller, cmd, image, info);
    const VkImage raw = image.vk();
    const std::uint32_t levels = image.mip_levels();
    const std::uint32_t layers =
        info.layer_count == VK_REMAINING_ARRAY_LAYERS ? image.array_layers() - info.base_layer : info.layer_count;
    const auto aspect = format_aspects(image.format());
    auto range = [&](std::uint32_t level, std::uint32_t count) {
        return VkImageSubresourceRange{aspect, level, count, info.base_layer, layers};
    };
    constexpr auto blit = VK_PIPELINE_STAGE_2_BLIT_BIT;
    constexpr auto read = VK_ACCESS_2_TRANSFER_READ_BIT;
    constexpr auto write = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    // Level 0 becomes a blit source; the others blit destinations (their old
    // contents are not needed, hence UNDEFINED).
    VkImageMemoryBarrier2 start[2] = {
        image_barrier(raw, range(0, 1), info.base_layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, info.src_stage,
                      info.src_access, blit, read),
        image_barrier(raw, range(1, VK_REMAINING_MIP_LEVELS), VK_IMAGE_LAYOUT_UNDEFINED,
                      VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE, blit, write)};
    cmd.pipeline_barrier({}, {}, Span(start, levels > 1 ? 2 : 1));
    for (std::uint32_t level = 1; level < levels; ++level) {
        VkImageBlit region{};
        region.srcSubresource = {aspect, level - 1, info.base_layer, layers};
        region.srcOffsets[1] = end_of(image.extent(level - 1));
        region.dstSubresource = {aspect, level, info.base_layer, layers};
        region.dstOffsets[1] = end_of(image.extent(level));
        cmd.blit_image(raw, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, raw, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                       Span(&region, 1), info.filter);
        // The level just written is the next blit's source.
        auto next = image_barrier(raw, range(level, 1), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                  VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, blit, write, blit, read);
        cmd.pipeline_barrier({}, {}, Span(&next, 1));
    }
    auto done = image_barrier(raw, range(0, levels), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, info.final_layout, blit,
                              write, info.dst_stage, info.dst_access);
    cmd.pipeline_barrier({}, {}, Span(&done, 1));
}

// Queue labels

namespace {
// Calls a begin- or insert-label function (null without VK_EXT_debug_utils)
// under the queue's lock: Vulkan requires queue calls to be synchronised.
void label_queue(PFN_vkQueueInsertDebugUtilsLabelEXT f, detail::QueueState& queue, const char* name,
                 const LabelColor& color) {
    if (!f) return;
    const VkDebugUtilsLabelEXT label = detail::debug_label(name, color);
    LockGuard lock(queue.mutex);
    f(queue.queue, &label);
}
}  // namespace

void Queue::begin_label(const char* name, const LabelColor& color) const {
    label_queue(device_.fn().vkQueueBeginDebugUtilsLabelEXT, *queue_, name, color);
}

void Queue::end_label() const {
    auto f = device_.fn().vkQueueEndDebugUtilsLabelEXT;
    if (!f) return;
    LockGuard lock(queue_->mutex);
    f(queue_->queue);
}

void Queue::insert_label(const char* name, const LabelColor& color) const {
    label_queue(device_.fn().vkQueueInsertDebugUtilsLabelEXT, *queue_, name, color);
}

VKRC_END_NAMESPACE
