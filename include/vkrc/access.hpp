// Barriers by named use: what a resource is used for at some point of a
// command stream (a colour attachment written, an image sampled in the
// fragment shader, a buffer the host reads, ...) names its pipeline stage,
// access and, for images, layout; a barrier goes from one use to the next.
//
//     cmd.pipeline_barrier({}, {}, std::array{
//         vkrc::image_barrier(shadow_map, vkrc::use::depth_attachment, vkrc::use::sampled(FRAGMENT))});
//
// Every use is a constexpr value (the tables below), and the helpers only
// fill the structs that vkrc::image_barrier, buffer_barrier and
// memory_barrier fill: nothing is looked up or stored while recording.
//
// vkrc keeps no per-image record of its last use: the order in which command
// buffers are recorded is not the order in which the GPU runs them (several
// threads, secondaries, buffers recorded ahead), so a record kept at
// recording time would name the wrong previous use, and under vkrc::mt it
// would need a lock on the recording path. The program names both uses.
#pragma once

#include "vkrc/barrier.hpp"
#include "vkrc/resource.hpp"

VKRC_BEGIN_NAMESPACE

// One use of a resource: the stages that use it, what they do to it and, for
// an image, the layout it must be in. Buffers and memory ignore layout.
struct Use {
    VkPipelineStageFlags2 stage = VK_PIPELINE_STAGE_2_NONE;
    VkAccessFlags2 access = VK_ACCESS_2_NONE;
    VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;

    friend constexpr bool operator==(const Use&, const Use&) = default;
};

// The vocabulary. A write use must be followed by a barrier before any other
// use; read uses may follow one another without one when the layout stays.
namespace use {

// Nothing yet: a new resource, or contents the next use overwrites.
inline constexpr Use none{};
// Written as a colour attachment (dynamic rendering or a render pass).
inline constexpr Use colour_attachment_write{VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                                             VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                                             VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
// Read and written by depth (and stencil) tests.
inline constexpr Use depth_attachment{
    VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
    VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
// Read by depth (and stencil) tests only, in the read-only layout.
inline constexpr Use depth_attachment_read{
    VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT, VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL};
// Sampled (or read as an input texel) by the shaders of stage, e.g.
// VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT.
constexpr Use sampled(VkPipelineStageFlags2 stage) noexcept {
    return {stage, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
}
// Read as a uniform buffer by the shaders of stage.
constexpr Use uniform_read(VkPipelineStageFlags2 stage) noexcept { return {stage, VK_ACCESS_2_UNIFORM_READ_BIT}; }
// A storage image or buffer in a compute shader.
inline constexpr Use compute_storage_read{VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT,
                                          VK_IMAGE_LAYOUT_GENERAL};
inline constexpr Use compute_storage_write{VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                           VK_IMAGE_LAYOUT_GENERAL};
inline constexpr Use compute_storage_read_write{
    VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
    VK_IMAGE_LAYOUT_GENERAL};
// The source or destination of a copy, blit, resolve or clear.
inline constexpr Use transfer_src{VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
                                  VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
inline constexpr Use transfer_dst{VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                  VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL};
// Vertex and index buffers, and indirect draw or dispatch parameters.
inline constexpr Use vertex_input{VK_PIPELINE_STAGE_2_VERTEX_ATTRIBUTE_INPUT_BIT,
                                  VK_ACCESS_2_VERTEX_ATTRIBUTE_READ_BIT};
inline constexpr Use index_input{VK_PIPELINE_STAGE_2_INDEX_INPUT_BIT, VK_ACCESS_2_INDEX_READ_BIT};
inline constexpr Use indirect_read{VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT, VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT};
// Read or written by the host (mapped memory) after or before the GPU's use.
inline constexpr Use host_read{VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT, VK_IMAGE_LAYOUT_GENERAL};
inline constexpr Use host_write{VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_WRITE_BIT, VK_IMAGE_LAYOUT_GENERAL};
// A swapchain image just acquired: its contents undefined, its acquire
// semaphore waited on at the colour-output stage (vkrc::Frame::acquire_stage).
inline constexpr Use acquired{VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT};
// Handed to the presentation engine (vkQueuePresentKHR orders itself after
// the semaphore the submit signals, hence no stage); a vkrc::Frame names
// the layout its presenter wants in present_layout.
constexpr Use presented(VkImageLayout layout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR) noexcept {
    return {VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE, layout};
}
inline constexpr Use present = presented();

// The previous use of contents the next use does not need: the barrier still
// orders the next use after it, but the layout transition starts from
// UNDEFINED and may discard them.
constexpr Use discarded(Use previous) noexcept {
    previous.layout = VK_IMAGE_LAYOUT_UNDEFINED;
    return previous;
}

}  // namespace use

// The barrier that makes the image ready for its next use after its
// previous one: every level and layer of every aspect of its format (depth
// and/or stencil, or colour).
inline VkImageMemoryBarrier2 image_barrier(const Image& image, Use previous, Use next) {
    return image_barrier(image.vk(), previous.layout, next.layout, previous.stage, previous.access, next.stage,
                         next.access, format_aspects(image.format()));
}
// The same over range (see mip_range and layer_range; their aspect is the caller's).
inline VkImageMemoryBarrier2 image_barrier(const Image& image, const VkImageSubresourceRange& range, Use previous,
                                           Use next) {
    return image_barrier(image.vk(), range, previous.layout, next.layout, previous.stage, previous.access, next.stage,
                         next.access);
}
// The buffer's size bytes from offset (VK_WHOLE_SIZE: to the end) between two uses.
inline VkBufferMemoryBarrier2 buffer_barrier(const Buffer& buffer, Use previous, Use next, VkDeviceSize offset = 0,
                                             VkDeviceSize size = VK_WHOLE_SIZE) {
    return buffer_barrier(buffer.vk(), previous.stage, previous.access, next.stage, next.access, offset, size);
}
// All memory between two uses (layouts ignored).
inline VkMemoryBarrier2 memory_barrier(Use previous, Use next) noexcept {
    return memory_barrier(previous.stage, previous.access, next.stage, next.access);
}

VKRC_END_NAMESPACE
