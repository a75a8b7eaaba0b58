// Issue 14's pipeline state: specialization constants on compute, vertex and
// fragment stages, and the full graphics state (stencil on both faces, per-
// attachment blending with constants, static viewports and scissors,
// multisampling with sample shading and alpha to coverage, a view mask,
// pipeline flags and next), each checked on read-back pixels.
#include "support/vk_test.hpp"

#include "shaders/spec_color.frag.h"
#include "shaders/spec_fill.comp.h"
#include "shaders/half_left.geom.h"
#include "shaders/spec_rect.vert.h"
#include "shaders/tess_pass.tesc.h"
#include "shaders/tess_pass.tese.h"

#include <array>
#include <cstddef>
#include <functional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace {

using vkrc_test::Rgba;
using vkrc_test::VulkanTest;
constexpr VkFormat rgba8 = VK_FORMAT_R8G8B8A8_UNORM;
constexpr std::uint32_t size = 8;
constexpr Rgba black{0, 0, 0, 255};

template <class T>
std::span<const std::byte> bytes_of(const T& value) {
    return std::as_bytes(std::span(&value, 1));
}

// Colour targets, an optional depth-stencil one, and read-back of target 0..n.
struct Targets {
    const vkrc::Device& device;
    std::vector<vkrc::Image> images;
    std::vector<vkrc::ImageView> views;
    vkrc::Image depth;
    vkrc::ImageView depth_view;
    vkrc::Buffer pixels;
    Targets(const vkrc::Device& d, std::size_t colors, VkFormat depth_format = VK_FORMAT_UNDEFINED)
        : device(d),
          pixels(vkrc::Buffer::create(d, {.size = colors * size * size * 4,
                                          .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                          .memory = {.usage = vkrc::MemoryUsage::readback}})) {
        for (std::size_t i = 0; i < colors; ++i) {
            images.push_back(vkrc::Image::create(
                d, {.format = rgba8,
                    .extent = {size, size, 1},
                    .usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT}));
            views.push_back(vkrc::ImageView::create(images.back()));
        }
        if (depth_format != VK_FORMAT_UNDEFINED) {
            depth = vkrc::Image::create(d, {.format = depth_format,
                                            .extent = {size, size, 1},
                                            .usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT});
            depth_view = vkrc::ImageView::create(depth);
        }
    }
    void begin(const vkrc::CommandBuffer& cmd, std::span<const VkClearColorValue> clears,
               std::uint32_t view_mask = 0) const {
        std::vector<VkImageMemoryBarrier2> in;
        std::vector<vkrc::RenderingAttachment> colors;
        for (std::size_t i = 0; i < images.size(); ++i) {
            in.push_back(vkrc::image_barrier(images[i].vk(), VK_IMAGE_LAYOUT_UNDEFINED,
                                             VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
                                             VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                                             VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT));
            colors.push_back({.image_view = views[i].vk()});
            colors.back().clear_value.color = clears[i];
        }
        vkrc::RenderingAttachment ds{.image_view = depth_view ? depth_view.vk() : VK_NULL_HANDLE,
                                     .image_layout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
                                     .store_op = VK_ATTACHMENT_STORE_OP_DONT_CARE};
        ds.clear_value.depthStencil = {1.0f, 0};
        if (depth) {
            in.push_back(vkrc::image_barrier(
                depth.vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
                VK_PIPELINE_STAGE_2_NONE, 0,
                VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT));
        }
        cmd.pipeline_barrier({}, {}, in);
        cmd.begin_rendering({.render_area = {{0, 0}, {size, size}},
                             .color_attachments = colors,
                             .depth_attachment = depth ? &ds : nullptr,
                             .stencil_attachment = depth ? &ds : nullptr,
                             .view_mask = view_mask});
    }
    void end(const vkrc::CommandBuffer& cmd) const {
        cmd.end_rendering();
        for (std::size_t i = 0; i < images.size(); ++i) {
            auto out = vkrc::image_barrier(
                images[i].vk(), VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
            cmd.pipeline_barrier({}, {}, std::span(&out, 1));
            VkBufferImageCopy region{};
            region.bufferOffset = i * size * size * 4;
            region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
            region.imageExtent = {size, size, 1};
            cmd.copy_image_to_buffer(images[i], VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, pixels, std::span(&region, 1));
        }
        auto to_host = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                            VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
        cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    }
    Rgba at(std::size_t target, std::uint32_t x, std::uint32_t y) const {
        return pixels.allocation().read_value<Rgba>(target * size * size * 4 + (y * size + x) * 4);
    }
};

void run(const vkrc::Queue& queue, const std::function<void(const vkrc::CommandBuffer&)>& record) {
    auto pool = vkrc::CommandPool::create(queue.device(), {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    record(cmd);
    cmd.end();
    auto fence = vkrc::Fence::create(queue.device());
    vkrc::submit(queue, {.command_buffers = std::span(&cmd, 1)}, fence);
    ASSERT_EQ(fence.wait(), VK_SUCCESS);
}

// The graphics pipeline of spec_rect.vert and spec_color.frag with its constants.
vkrc::GraphicsPipelineBuilder rect_builder(const vkrc::Device& device, const float& right, const float (&color)[2]) {
    static const VkSpecializationMapEntry right_entry{0, 0, sizeof(float)};
    static const VkSpecializationMapEntry color_entries[] = {{0, 0, sizeof(float)}, {1, sizeof(float), sizeof(float)}};
    vkrc::GraphicsPipelineBuilder b(vkrc::PipelineLayout::create(device));
    b.shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::spec_rect_vert))
        .shader(VK_SHADER_STAGE_FRAGMENT_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::spec_color_frag))
        .specialization(VK_SHADER_STAGE_VERTEX_BIT, {std::span(&right_entry, 1), bytes_of(right)})
        .specialization(VK_SHADER_STAGE_FRAGMENT_BIT, {color_entries, bytes_of(color)})
        .cull_mode(VK_CULL_MODE_NONE);
    return b;
}

void viewport_and_scissor(const vkrc::CommandBuffer& cmd) { cmd.set_viewport_and_scissor({size, size}); }

// Specialization

TEST_F(VulkanTest, SpecializationConstantsOfComputeVertexAndFragmentStages) {
    // Compute: the workgroup size and two values.
    const std::uint32_t constants[] = {4, 100, 3};
    const VkSpecializationMapEntry entries[] = {{0, 0, 4}, {1, 4, 4}, {2, 8, 4}};
    auto buffer = vkrc::Buffer::create(
        device,
        {.size = 8 * 4, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, .memory = {.usage = vkrc::MemoryUsage::readback}});
    auto set_layout =
        vkrc::DescriptorSetLayout::create(device, {.bindings = {{.binding = 0,
                                                                 .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                                                 .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT}}});
    auto layout = vkrc::PipelineLayout::create(device, {.set_layouts = {set_layout}});
    auto compute = vkrc::ComputePipeline::create(
        layout, {.module = vkrc::ShaderModule::create(device, vkrc_shaders::spec_fill_comp),
                 .specialization = {entries, std::as_bytes(std::span(constants))}});
    auto descriptors =
        vkrc::DescriptorPool::create(device, {.max_sets = 1, .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
    auto set = descriptors.allocate(set_layout);
    set.write_buffer(0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, buffer);

    // Graphics: the vertex stage's right edge, the fragment stage's colour.
    const float right = 0.0f, color[2] = {1.0f, 0.5f};
    auto graphics = rect_builder(device, right, color).rendering(std::array{rgba8}).build();
    Targets targets(device, 1);
    run(queue, [&](const vkrc::CommandBuffer& cmd) {
        cmd.bind_pipeline(compute);
        cmd.bind_descriptor_set(compute, 0, set);
        cmd.dispatch(2);
        auto to_host = vkrc::buffer_barrier(buffer.vk(), VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                            VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                                            VK_ACCESS_2_HOST_READ_BIT);
        cmd.pipeline_barrier({}, std::span(&to_host, 1), {});
        const VkClearColorValue clear{{0, 0, 0, 1}};
        targets.begin(cmd, std::span(&clear, 1));
        cmd.bind_pipeline(graphics);
        viewport_and_scissor(cmd);
        cmd.draw(6);
        targets.end(cmd);
    });
    for (std::uint32_t i = 0; i < 8; ++i) {
        EXPECT_EQ(buffer.allocation().read_value<std::uint32_t>(i * 4), 100 + 3 * (i % 4)) << i;
    }
    const auto left = targets.at(0, 1, 4);
    EXPECT_EQ(left[0], 255);
    EXPECT_NEAR(left[1], 128, 1);
    EXPECT_EQ(targets.at(0, 6, 4), black);
}

TEST_F(VulkanTest, SpecializationRejectsEntriesOutsideTheData) {
    const std::uint32_t value = 1;
    const VkSpecializationMapEntry past_end{0, 2, 4};
    vkrc::GraphicsPipelineBuilder b(vkrc::PipelineLayout::create(device));
    EXPECT_THROW(b.specialization(VK_SHADER_STAGE_FRAGMENT_BIT, {std::span(&past_end, 1), bytes_of(value)}),
                 vkrc::UsageError);
    // A stage without a shader.
    const VkSpecializationMapEntry ok{0, 0, 4};
    b.shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::spec_rect_vert))
        .specialization(VK_SHADER_STAGE_FRAGMENT_BIT, {std::span(&ok, 1), bytes_of(value)})
        .rendering(std::array{rgba8});
    EXPECT_THROW(b.build(), vkrc::UsageError);
    auto layout = vkrc::PipelineLayout::create(device);
    EXPECT_THROW(vkrc::ComputePipeline::create(
                     layout, {.module = vkrc::ShaderModule::create(device, vkrc_shaders::spec_fill_comp),
                              .specialization = {std::span(&past_end, 1), bytes_of(value)}}),
                 vkrc::UsageError);
}

// PipelineState

// A device with the optional features these tests use, or empty (the test skips).
vkrc::Device full_state_device(const vkrc::PhysicalDevice& physical, std::string& missing) {
    VkPhysicalDeviceVulkan11Features f11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
    VkPhysicalDeviceFeatures2 f{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f11};
    physical.fn().vkGetPhysicalDeviceFeatures2(physical.vk(), &f);
    const auto& a = f.features;
    for (auto [ok, name] : {std::pair{a.depthClamp, "depthClamp"},
                            {a.independentBlend, "independentBlend"},
                            {a.multiViewport, "multiViewport"},
                            {a.sampleRateShading, "sampleRateShading"},
                            {f11.multiview, "multiview"}}) {
        if (!ok) missing += std::string(missing.empty() ? "" : ", ") + name;
    }
    if (!missing.empty()) return {};
    vkrc::DeviceCreateInfo info;
    info.enabled_features.depthClamp = VK_TRUE;
    info.enabled_features.independentBlend = VK_TRUE;
    info.enabled_features.multiViewport = VK_TRUE;
    info.enabled_features.sampleRateShading = VK_TRUE;
    info.vulkan11_features.multiview = VK_TRUE;
    return vkrc::Device::create(physical, info);
}

#define FULL_STATE_DEVICE(dev)                            \
  std::string missing;                                    \
  auto dev = full_state_device(physical_device, missing); \
  if (!dev) GTEST_SKIP() << "the device lacks " << missing;

VkFormat stencil_format(const vkrc::PhysicalDevice& physical) {
    for (VkFormat f : {VK_FORMAT_D32_SFLOAT_S8_UINT, VK_FORMAT_D24_UNORM_S8_UINT}) {
        VkFormatProperties p{};
        physical.fn().vkGetPhysicalDeviceFormatProperties(physical.vk(), f, &p);
        if (p.optimalTilingFeatures & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT) return f;
    }
    return VK_FORMAT_UNDEFINED;
}

TEST_F(VulkanTest, PipelineStateStencilOnBothFacesAndRasterization) {
    FULL_STATE_DEVICE(dev);
    const VkFormat ds = stencil_format(physical_device);
    ASSERT_NE(ds, VK_FORMAT_UNDEFINED);
    const VkStencilOpState mark_op{
        VK_STENCIL_OP_KEEP, VK_STENCIL_OP_REPLACE, VK_STENCIL_OP_KEEP, VK_COMPARE_OP_ALWAYS, 0xff, 0xff, 1};
    // Marks stencil 1 on the left half, writing no colour.
    const VkPipelineColorBlendAttachmentState no_color{};
    const float half = 0.0f, full = 1.0f, yellow[2] = {1.0f, 1.0f};
    auto mark = rect_builder(dev, half, yellow)
                    .rendering(std::array{rgba8}, ds, ds)
                    .blend_attachments(std::span(&no_color, 1))
                    .depth_stencil({.depth_test_enable = false,
                                    .depth_write_enable = false,
                                    .stencil_test_enable = true,
                                    .front = mark_op,
                                    .back = mark_op})
                    .build();
    // Draws everywhere the stencil is 1, through the back face's state: the
    // rect is clockwise-front here, so it is a back face, and the front
    // state (NEVER) would draw nothing.
    VkStencilOpState never = mark_op, equal = mark_op;
    never.compareOp = VK_COMPARE_OP_NEVER;
    equal.compareOp = VK_COMPARE_OP_EQUAL;
    equal.passOp = VK_STENCIL_OP_KEEP;
    auto test = rect_builder(dev, full, yellow)
                    .rendering(std::array{rgba8}, ds, ds)
                    .rasterization({.depth_clamp_enable = true,
                                    .cull_mode = VK_CULL_MODE_FRONT_BIT,
                                    .front_face = VK_FRONT_FACE_CLOCKWISE,
                                    .depth_bias_enable = true,
                                    .depth_bias_constant_factor = 1.0f,
                                    .line_width = 1.0f})
                    .depth_stencil({.depth_test_enable = true,
                                    .depth_write_enable = false,
                                    .depth_compare_op = VK_COMPARE_OP_LESS_OR_EQUAL,
                                    .stencil_test_enable = true,
                                    .front = never,
                                    .back = equal})
                    .flags(VK_PIPELINE_CREATE_DISABLE_OPTIMIZATION_BIT)
                    .build();
    Targets targets(dev, 1, ds);
    run(dev.default_queue(), [&](const vkrc::CommandBuffer& cmd) {
        const VkClearColorValue clear{{0, 0, 0, 1}};
        targets.begin(cmd, std::span(&clear, 1));
        viewport_and_scissor(cmd);
        cmd.bind_pipeline(mark);
        cmd.draw(6);
        cmd.bind_pipeline(test);
        cmd.draw(6);
        targets.end(cmd);
    });
    EXPECT_EQ(targets.at(0, 1, 4), (Rgba{255, 255, 0, 255}));
    EXPECT_EQ(targets.at(0, 6, 4), black);
}

TEST_F(VulkanTest, PipelineStatePerAttachmentBlendAndStaticViewports) {
    FULL_STATE_DEVICE(dev);
    const VkPipelineColorBlendAttachmentState blends[] = {
        // Target 0: colour times the blend constants.
        {VK_TRUE, VK_BLEND_FACTOR_CONSTANT_COLOR, VK_BLEND_FACTOR_ZERO, VK_BLEND_OP_ADD, VK_BLEND_FACTOR_ONE,
         VK_BLEND_FACTOR_ZERO, VK_BLEND_OP_ADD,
         VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT},
        // Target 1: not written.
        {}};
    // Two static viewports and scissors (only the first is used by the
    // shader); the scissor keeps the top half.
    const VkViewport viewports[] = {{0, 0, float(size), float(size), 0, 1}, {0, 0, 1, 1, 0, 1}};
    const VkRect2D scissors[] = {{{0, 0}, {size, size / 2}}, {{0, 0}, {1, 1}}};
    const float full = 1.0f, yellow[2] = {1.0f, 1.0f};
    auto pipeline = rect_builder(dev, full, yellow)
                        .rendering(std::array{rgba8, rgba8})
                        .blend_attachments(blends)
                        .blend_constants({0.5f, 0.25f, 1.0f, 1.0f})
                        .viewports(viewports)
                        .scissors(scissors)
                        .dynamic_states({})
                        .build();
    Targets targets(dev, 2);
    run(dev.default_queue(), [&](const vkrc::CommandBuffer& cmd) {
        const VkClearColorValue clears[] = {{{0, 0, 0, 1}}, {{0, 0, 1, 1}}};
        targets.begin(cmd, clears);
        cmd.bind_pipeline(pipeline);
        cmd.draw(6);
        targets.end(cmd);
    });
    EXPECT_TRUE(vkrc_test::within_one(targets.at(0, 4, 1), Rgba{128, 64, 0, 255}));  // 0.5 blended
    EXPECT_EQ(targets.at(0, 4, 6), black);                                           // scissored
    EXPECT_EQ(targets.at(1, 4, 1), (Rgba{0, 0, 255, 255}));
}

TEST_F(VulkanTest, PipelineStateRejectsMismatchedCounts) {
    const float full = 1.0f, yellow[2] = {1.0f, 1.0f};
    const VkPipelineColorBlendAttachmentState one{};
    EXPECT_THROW(rect_builder(device, full, yellow)
                     .rendering(std::array{rgba8, rgba8})
                     .blend_attachments(std::span(&one, 1))
                     .build(),
                 vkrc::UsageError);
    const VkViewport viewports[2] = {};
    const VkRect2D scissor{};
    EXPECT_THROW(rect_builder(device, full, yellow).rendering(std::array{rgba8}).dynamic_states({}).build(),
                 vkrc::UsageError);  // static viewport and scissor not given
    EXPECT_THROW(rect_builder(device, full, yellow)
                     .rendering(std::array{rgba8})
                     .viewports(viewports)
                     .scissors(std::span(&scissor, 1))
                     .build(),
                 vkrc::UsageError);
    EXPECT_THROW(rect_builder(device, full, yellow)
                     .rendering(std::array{rgba8})
                     .tessellation(0)
                     .topology(VK_PRIMITIVE_TOPOLOGY_PATCH_LIST)
                     .shader(VK_SHADER_STAGE_TESSELLATION_CONTROL_BIT,
                             vkrc::ShaderModule::create(device, vkrc_shaders::spec_rect_vert))
                     .build(),
                 vkrc::UsageError);
}

TEST_F(VulkanTest, PipelineStateMultisampleShadingAndViewMask) {
    FULL_STATE_DEVICE(dev);
    const float full = 1.0f, red[2] = {1.0f, 0.0f};
    VkPipelineCreationFeedback feedback{};
    VkPipelineCreationFeedbackCreateInfo feedback_info{VK_STRUCTURE_TYPE_PIPELINE_CREATION_FEEDBACK_CREATE_INFO};
    feedback_info.pPipelineCreationFeedback = &feedback;
    auto pipeline = rect_builder(dev, full, red)
                        .rendering(std::array{rgba8})
                        .multisample({.rasterization_samples = VK_SAMPLE_COUNT_4_BIT,
                                      .sample_shading_enable = true,
                                      .min_sample_shading = 1.0f,
                                      .alpha_to_coverage_enable = true})
                        .view_mask(1)
                        .next(&feedback_info)
                        .build();
    auto msaa = vkrc::Image::create(dev, {.format = rgba8,
                                          .extent = {size, size, 1},
                                          .samples = VK_SAMPLE_COUNT_4_BIT,
                                          .usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT});
    auto msaa_view = vkrc::ImageView::create(msaa);
    Targets targets(dev, 1);
    run(dev.default_queue(), [&](const vkrc::CommandBuffer& cmd) {
        const VkImageMemoryBarrier2 in[] = {
            vkrc::image_barrier(msaa.vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                VK_PIPELINE_STAGE_2_NONE, 0, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                                VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT),
            vkrc::image_barrier(targets.images[0].vk(), VK_IMAGE_LAYOUT_UNDEFINED,
                                VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
                                VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                                VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT)};
        cmd.pipeline_barrier({}, {}, in);
        vkrc::RenderingAttachment color{.image_view = msaa_view.vk(),
                                        .store_op = VK_ATTACHMENT_STORE_OP_DONT_CARE,
                                        .resolve_mode = VK_RESOLVE_MODE_AVERAGE_BIT,
                                        .resolve_image_view = targets.views[0].vk()};
        color.clear_value.color = {{0, 0, 0, 1}};
        cmd.begin_rendering(
            {.render_area = {{0, 0}, {size, size}}, .color_attachments = std::span(&color, 1), .view_mask = 1});
        cmd.bind_pipeline(pipeline);
        viewport_and_scissor(cmd);
        cmd.draw(6);
        targets.end(cmd);
    });
    EXPECT_EQ(targets.at(0, 4, 4), (Rgba{255, 0, 0, 255}));
}

TEST_F(VulkanTest, PipelineStateTessellationAndGeometryStages) {
    VkPhysicalDeviceFeatures supported{};
    physical_device.fn().vkGetPhysicalDeviceFeatures(physical_device.vk(), &supported);
    if (!supported.tessellationShader || !supported.geometryShader)
        GTEST_SKIP() << "the device lacks tessellationShader or geometryShader";
    vkrc::DeviceCreateInfo info;
    info.enabled_features.tessellationShader = VK_TRUE;
    info.enabled_features.geometryShader = VK_TRUE;
    auto dev = vkrc::Device::create(physical_device, info);
    // The full-screen rect as two patches of three, tessellated as they are,
    // then squeezed into the left half by the geometry stage.
    const float full = 1.0f, green[2] = {0.0f, 1.0f};
    auto pipeline =
        rect_builder(dev, full, green)
            .shader(VK_SHADER_STAGE_TESSELLATION_CONTROL_BIT,
                    vkrc::ShaderModule::create(dev, vkrc_shaders::tess_pass_tesc))
            .shader(VK_SHADER_STAGE_TESSELLATION_EVALUATION_BIT,
                    vkrc::ShaderModule::create(dev, vkrc_shaders::tess_pass_tese))
            .shader(VK_SHADER_STAGE_GEOMETRY_BIT, vkrc::ShaderModule::create(dev, vkrc_shaders::half_left_geom))
            .topology(VK_PRIMITIVE_TOPOLOGY_PATCH_LIST)
            .tessellation(3)
            .rendering(std::array{rgba8})
            .build();
    Targets targets(dev, 1);
    run(dev.default_queue(), [&](const vkrc::CommandBuffer& cmd) {
        const VkClearColorValue clear{{0, 0, 0, 1}};
        targets.begin(cmd, std::span(&clear, 1));
        cmd.bind_pipeline(pipeline);
        viewport_and_scissor(cmd);
        cmd.draw(6);
        targets.end(cmd);
    });
    EXPECT_EQ(targets.at(0, 1, 4), (Rgba{0, 255, 0, 255}));
    EXPECT_EQ(targets.at(0, 6, 4), black);
}

// RawInterop: a pipeline bound by its raw handle and sets by its layout, as
// for pipelines made by other code.
TEST_F(VulkanTest, RawInteropBindsPipelineAndSetsByLayout) {
    const std::uint32_t constants[] = {4, 7, 2};
    const VkSpecializationMapEntry entries[] = {{0, 0, 4}, {1, 4, 4}, {2, 8, 4}};
    auto buffer = vkrc::Buffer::create(
        device,
        {.size = 4 * 4, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, .memory = {.usage = vkrc::MemoryUsage::readback}});
    auto set_layout =
        vkrc::DescriptorSetLayout::create(device, {.bindings = {{.binding = 0,
                                                                 .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                                                 .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT}}});
    auto layout = vkrc::PipelineLayout::create(device, {.set_layouts = {set_layout}});
    auto compute = vkrc::ComputePipeline::create(
        layout, {.module = vkrc::ShaderModule::create(device, vkrc_shaders::spec_fill_comp),
                 .specialization = {entries, std::as_bytes(std::span(constants))}});
    auto descriptors =
        vkrc::DescriptorPool::create(device, {.max_sets = 1, .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
    auto set = descriptors.allocate(set_layout);
    set.write_buffer(0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, buffer);
    run(queue, [&](const vkrc::CommandBuffer& cmd) {
        cmd.bind_pipeline(VK_PIPELINE_BIND_POINT_COMPUTE, compute.vk());
        const VkDescriptorSet sets[] = {set.vk()};
        cmd.bind_descriptor_sets(VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, sets);
        cmd.dispatch(1);
        auto to_host = vkrc::buffer_barrier(buffer.vk(), VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                            VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                                            VK_ACCESS_2_HOST_READ_BIT);
        cmd.pipeline_barrier({}, std::span(&to_host, 1), {});
    });
    EXPECT_EQ(buffer.allocation().read_value<std::uint32_t>(12), 7u + 2u * 3u);
}

}  // namespace
