// Issue 14's dynamic state: every Vulkan 1.0 and 1.3 core setter recorded
// against a pipeline that declares it, with the effect of the visible ones
// (culling, front face, rasterizer discard, blend constants, viewport and
// scissor with count) read back.
#include "support/vk_test.hpp"

#include "shaders/push_color.frag.h"
#include "shaders/rect.vert.h"

#include <array>
#include <span>

namespace {

using vkrc_test::Rgba;
using vkrc_test::VulkanTest;
constexpr VkFormat rgba8 = VK_FORMAT_R8G8B8A8_UNORM;
constexpr std::uint32_t size = 8;

struct RectPush {
    float color[4];
    float bounds[4];  // x0 y0 x1 y1, NDC
    float depth;
};

vkrc::GraphicsPipelineBuilder rect_builder(const vkrc::Device& device) {
    auto layout = vkrc::PipelineLayout::create(
        device,
        {.push_constant_ranges = {{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(RectPush)}}});
    vkrc::GraphicsPipelineBuilder b(layout);
    b.shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::rect_vert))
        .shader(VK_SHADER_STAGE_FRAGMENT_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::push_color_frag))
        .rendering(std::array{rgba8});
    return b;
}

void draw_rect(const vkrc::CommandBuffer& cmd, const vkrc::Pipeline& p, float x0, float y0, float x1, float y1) {
    cmd.push_constants(p.layout(), VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                       RectPush{{1, 1, 1, 1}, {x0, y0, x1, y1}, 0.0f});
    cmd.draw(6);
}

// The states pipeline "all" declares and the test sets before its first draw.
constexpr VkDynamicState all_states[] = {VK_DYNAMIC_STATE_LINE_WIDTH,
                                         VK_DYNAMIC_STATE_DEPTH_BIAS,
                                         VK_DYNAMIC_STATE_BLEND_CONSTANTS,
                                         VK_DYNAMIC_STATE_DEPTH_BOUNDS,
                                         VK_DYNAMIC_STATE_STENCIL_COMPARE_MASK,
                                         VK_DYNAMIC_STATE_STENCIL_WRITE_MASK,
                                         VK_DYNAMIC_STATE_STENCIL_REFERENCE,
                                         VK_DYNAMIC_STATE_CULL_MODE,
                                         VK_DYNAMIC_STATE_FRONT_FACE,
                                         VK_DYNAMIC_STATE_PRIMITIVE_TOPOLOGY,
                                         VK_DYNAMIC_STATE_DEPTH_TEST_ENABLE,
                                         VK_DYNAMIC_STATE_DEPTH_WRITE_ENABLE,
                                         VK_DYNAMIC_STATE_DEPTH_COMPARE_OP,
                                         VK_DYNAMIC_STATE_DEPTH_BOUNDS_TEST_ENABLE,
                                         VK_DYNAMIC_STATE_STENCIL_TEST_ENABLE,
                                         VK_DYNAMIC_STATE_STENCIL_OP,
                                         VK_DYNAMIC_STATE_RASTERIZER_DISCARD_ENABLE,
                                         VK_DYNAMIC_STATE_DEPTH_BIAS_ENABLE,
                                         VK_DYNAMIC_STATE_PRIMITIVE_RESTART_ENABLE};

void set_everything_else(const vkrc::CommandBuffer& cmd) {
    cmd.set_line_width(1.0f);
    cmd.set_depth_bias(0.0f, 0.0f, 0.0f);
    cmd.set_blend_constants({0.5f, 0.25f, 1.0f, 1.0f});
    cmd.set_depth_bounds(0.0f, 1.0f);
    cmd.set_stencil_compare_mask(VK_STENCIL_FACE_FRONT_AND_BACK, 0xff);
    cmd.set_stencil_write_mask(VK_STENCIL_FACE_FRONT_AND_BACK, 0xff);
    cmd.set_stencil_reference(VK_STENCIL_FACE_FRONT_AND_BACK, 1);
    cmd.set_primitive_topology(VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST);
    cmd.set_depth_test_enable(false);
    cmd.set_depth_write_enable(false);
    cmd.set_depth_compare_op(VK_COMPARE_OP_ALWAYS);
    cmd.set_depth_bounds_test_enable(false);
    cmd.set_stencil_test_enable(false);
    cmd.set_stencil_op(VK_STENCIL_FACE_FRONT_AND_BACK, VK_STENCIL_OP_KEEP, VK_STENCIL_OP_REPLACE, VK_STENCIL_OP_KEEP,
                       VK_COMPARE_OP_ALWAYS);
    cmd.set_depth_bias_enable(false);
    cmd.set_primitive_restart_enable(false);
}

TEST_F(VulkanTest, DynamicStateEveryCoreSetter) {
    // Output = white * blend constants, so the constants show in the pixels.
    const VkPipelineColorBlendAttachmentState by_constants{
        VK_TRUE,
        VK_BLEND_FACTOR_CONSTANT_COLOR,
        VK_BLEND_FACTOR_ZERO,
        VK_BLEND_OP_ADD,
        VK_BLEND_FACTOR_ONE,
        VK_BLEND_FACTOR_ZERO,
        VK_BLEND_OP_ADD,
        VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT};
    auto all_builder = rect_builder(device);
    all_builder.blend(by_constants);
    for (auto s : all_states) all_builder.dynamic_state(s);
    auto all = all_builder.build();
    // Viewport and scissor counts dynamic too: replaces the default list.
    const VkDynamicState with_count[] = {VK_DYNAMIC_STATE_VIEWPORT_WITH_COUNT, VK_DYNAMIC_STATE_SCISSOR_WITH_COUNT,
                                         VK_DYNAMIC_STATE_VERTEX_INPUT_BINDING_STRIDE};
    auto counted = rect_builder(device).dynamic_states(with_count).build();

    auto image =
        vkrc::Image::create(device, {.format = rgba8,
                                     .extent = {size, size, 1},
                                     .usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
    auto view = vkrc::ImageView::create(image);
    auto pixels = vkrc::Buffer::create(device, {.size = size * size * 4,
                                                .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                                .memory = {.usage = vkrc::MemoryUsage::readback}});
    auto vertices = vkrc::Buffer::create(device, {.size = 64, .usage = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT});
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    auto in = vkrc::image_barrier(image.vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                  VK_PIPELINE_STAGE_2_NONE, 0, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                                  VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
    cmd.pipeline_barrier({}, {}, std::span(&in, 1));
    vkrc::RenderingAttachment color{.image_view = view.vk()};
    color.clear_value.color = {{0, 0, 0, 1}};
    cmd.begin_rendering({.render_area = {{0, 0}, {size, size}}, .color_attachments = std::span(&color, 1)});
    cmd.bind_pipeline(all);
    const VkViewport viewport{0, 0, float(size), float(size), 0, 1};
    const VkRect2D scissor{{0, 0}, {size, size}};
    cmd.set_viewports(0, std::span(&viewport, 1));
    cmd.set_scissors(0, std::span(&scissor, 1));
    set_everything_else(cmd);
    cmd.set_rasterizer_discard_enable(false);
    // rect.vert's rects are counter-clockwise: front faces, culled...
    cmd.set_cull_mode(VK_CULL_MODE_FRONT_BIT);
    cmd.set_front_face(VK_FRONT_FACE_COUNTER_CLOCKWISE);
    draw_rect(cmd, all, -1, -1, 0, 0);  // top left: culled
    // ...until clockwise faces are the front ones.
    cmd.set_front_face(VK_FRONT_FACE_CLOCKWISE);
    draw_rect(cmd, all, 0, -1, 1, 0);  // top right: drawn
    cmd.set_cull_mode(VK_CULL_MODE_NONE);
    cmd.set_rasterizer_discard_enable(true);
    draw_rect(cmd, all, -1, 0, 0, 1);  // bottom left: discarded
    cmd.set_rasterizer_discard_enable(false);
    draw_rect(cmd, all, 0, 0, 1, 1);  // bottom right: drawn

    cmd.bind_pipeline(counted);
    cmd.set_viewport_with_count(std::span(&viewport, 1));
    const VkRect2D corner{{0, size - 2}, {2, 2}};
    cmd.set_scissor_with_count(std::span(&corner, 1));
    const VkBuffer buffers[] = {vertices.vk()};
    const VkDeviceSize offsets[] = {0}, sizes[] = {64}, strides[] = {16};
    cmd.bind_vertex_buffers2(0, buffers, offsets, sizes, strides);
    draw_rect(cmd, counted, -1, -1, 1, 1);  // only the scissored bottom-left corner
    cmd.end_rendering();

    auto out =
        vkrc::image_barrier(image.vk(), VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                            VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                            VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    cmd.pipeline_barrier({}, {}, std::span(&out, 1));
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {size, size, 1};
    cmd.copy_image_to_buffer(image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, pixels, std::span(&region, 1));
    auto to_host = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                        VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    cmd.end();
    auto fence = vkrc::Fence::create(device);
    vkrc::submit(queue, {.command_buffers = std::span(&cmd, 1)}, fence);
    ASSERT_EQ(fence.wait(), VK_SUCCESS);

    auto at = [&](std::uint32_t x, std::uint32_t y) {
        return pixels.allocation().read_value<Rgba>((y * size + x) * 4);
    };
    const Rgba black{0, 0, 0, 255}, blended{128, 64, 255, 255}, white{255, 255, 255, 255};
    EXPECT_EQ(at(1, 1), black);                             // culled
    EXPECT_TRUE(vkrc_test::within_one(at(6, 1), blended));  // drawn after the front-face change
    EXPECT_EQ(at(3, 5), black);                             // discarded
    EXPECT_TRUE(vkrc_test::within_one(at(6, 6), blended));
    EXPECT_EQ(at(0, 7), white);  // the with-count scissor's corner
    EXPECT_EQ(at(3, 7), black);
}

}  // namespace
