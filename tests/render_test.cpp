// End-to-end GPU work through vkrc: compute writes, rendering with a render
// pass and with dynamic rendering, read back and compared exactly; and
// dropping every object right after submitting work that uses it.
#include "support/features.hpp"
#include "support/vk_test.hpp"

#include "shaders/fill_pattern.comp.h"
#include "shaders/push_color.frag.h"
#include "shaders/rect.vert.h"
#include "shaders/triangle.frag.h"
#include "shaders/triangle.vert.h"

#include <array>
#include <cstring>
#include <span>
#include <thread>
#include <vector>

namespace {

using vkrc_test::SyncValidatedTest;
using vkrc_test::VulkanTest;

constexpr std::uint32_t size = 64;
constexpr VkFormat color_format = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkFormat depth_format = VK_FORMAT_D32_SFLOAT;
using vkrc_test::Rgba;

std::uint32_t pattern(std::uint32_t i, std::uint32_t seed) { return (i * 2654435761u) ^ seed; }

struct FillParams {
    std::uint32_t count;
    std::uint32_t seed;
};

struct RectPush {
    float color[4];
    float bounds[4];  // x0 y0 x1 y1, NDC
    float depth;
};

vkrc::Buffer readback_buffer(const vkrc::Device& device, VkDeviceSize bytes, VkBufferUsageFlags usage) {
    return vkrc::Buffer::create(device,
                                {.size = bytes, .usage = usage, .memory = {.usage = vkrc::MemoryUsage::readback}});
}

vkrc::Image attachment_image(const vkrc::Device& device, VkFormat format, VkImageUsageFlags usage) {
    return vkrc::Image::create(device, {.format = format, .extent = {size, size, 1}, .usage = usage});
}

// The compute pipeline of fill_pattern.comp and the set that points it at a buffer.
struct Fill {
    vkrc::DescriptorSetLayout set_layout;
    vkrc::ComputePipeline pipeline;
    vkrc::DescriptorPool pool;
    vkrc::DescriptorSet set;

    Fill(const vkrc::Device& device, const vkrc::Buffer& target) {
        set_layout = vkrc::DescriptorSetLayout::create(
            device, {.bindings = {{.binding = 0,
                                   .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                   .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT}}});
        auto layout = vkrc::PipelineLayout::create(
            device, {.set_layouts = {set_layout},
                     .push_constant_ranges = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(FillParams)}}});
        pipeline =
            vkrc::ComputePipeline::create(layout, vkrc::ShaderModule::create(device, vkrc_shaders::fill_pattern_comp));
        pool = vkrc::DescriptorPool::create(device,
                                            {.max_sets = 1, .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
        set = pool.allocate(set_layout);
        set.write_buffer(0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, target);
    }
    void record(const vkrc::CommandBuffer& cmd, std::uint32_t count, std::uint32_t seed) const {
        cmd.bind_pipeline(pipeline);
        cmd.bind_descriptor_set(pipeline, 0, set);
        cmd.push_constants(pipeline.layout(), VK_SHADER_STAGE_COMPUTE_BIT, FillParams{count, seed});
        cmd.dispatch((count + 63) / 64);
    }
};

TEST_F(VulkanTest, ComputeWritesAKnownPattern) {
    constexpr std::uint32_t count = 1000, seed = 0xC0FFEE;
    auto buffer = readback_buffer(device, count * sizeof(std::uint32_t), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    Fill fill(device, buffer);
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    fill.record(cmd, count, seed);
    auto to_host = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                        VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    cmd.end();
    auto fence = vkrc::Fence::create(device);
    vkrc::submit(queue, {.command_buffers = std::span(&cmd, 1)}, fence);
    ASSERT_EQ(fence.wait(), VK_SUCCESS);
    std::vector<std::uint32_t> out(count);
    buffer.allocation().read(0, std::span(out));
    std::size_t mismatches = 0;
    for (std::uint32_t i = 0; i < count; ++i) mismatches += out[i] != pattern(i, seed);
    EXPECT_EQ(mismatches, 0u) << "first value " << out[0] << ", expected " << pattern(0, seed);
}

// Copies a colour image in TRANSFER_SRC_OPTIMAL to a readback buffer.
void record_readback(const vkrc::CommandBuffer& cmd, const vkrc::Image& image, const vkrc::Buffer& pixels) {
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {size, size, 1};
    cmd.copy_image_to_buffer(image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, pixels, std::span(&region, 1));
    auto to_host = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                        VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
}

Rgba pixel(const vkrc::Buffer& pixels, std::uint32_t x, std::uint32_t y) {
    return pixels.allocation().read_value<Rgba>((y * size + x) * 4);
}

void submit_and_wait(const vkrc::Queue& queue, const vkrc::CommandBuffer& cmd) {
    auto fence = vkrc::Fence::create(queue.device());
    vkrc::submit(queue, {.command_buffers = std::span(&cmd, 1)}, fence);
    ASSERT_EQ(fence.wait(), VK_SUCCESS);
}

constexpr Rgba red{255, 0, 0, 255}, green{0, 255, 0, 255}, blue{0, 0, 255, 255}, black{0, 0, 0, 255};

// A render pass and framebuffer; the triangle comes from a vertex buffer.
TEST_F(VulkanTest, TriangleThroughARenderPass) {
    struct Vertex {
        float position[2];
        float color[3];
    };
    // Counter-clockwise on screen (y points down in Vulkan's framebuffer).
    const Vertex vertices[] = {{{0.0f, -0.5f}, {1, 0, 0}}, {{-0.5f, 0.5f}, {1, 0, 0}}, {{0.5f, 0.5f}, {1, 0, 0}}};
    auto vertex_buffer = vkrc::Buffer::create(device, {.size = sizeof vertices,
                                                       .usage = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT,
                                                       .memory = {.usage = vkrc::MemoryUsage::upload}});
    vertex_buffer.allocation().write(0, vertices, 3);

    auto image =
        attachment_image(device, color_format, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    auto pixels = readback_buffer(device, size * size * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    auto render_pass = vkrc_test::clear_to_copy_render_pass(device, color_format);
    auto framebuffer = vkrc::Framebuffer::create(
        device,
        {.render_pass = render_pass, .attachments = {vkrc::ImageView::create(image)}, .width = size, .height = size});
    auto pipeline =
        vkrc::GraphicsPipelineBuilder(vkrc::PipelineLayout::create(device))
            .shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::triangle_vert))
            .shader(VK_SHADER_STAGE_FRAGMENT_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::triangle_frag))
            .vertex_binding(0, sizeof(Vertex))
            .vertex_attribute(0, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, position))
            .vertex_attribute(1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, color))
            .render_pass(render_pass)
            .build();

    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    VkClearValue clear{};
    clear.color = {{0.0f, 0.0f, 1.0f, 1.0f}};
    cmd.begin_render_pass(render_pass, framebuffer, {{0, 0}, {size, size}}, std::span(&clear, 1));
    cmd.bind_pipeline(pipeline);
    cmd.set_viewport_and_scissor(framebuffer.extent());
    cmd.bind_vertex_buffer(0, vertex_buffer);
    cmd.draw(3);
    cmd.end_render_pass();
    record_readback(cmd, image, pixels);
    cmd.end();
    submit_and_wait(queue, cmd);

    EXPECT_EQ(pixel(pixels, 32, 32), red);  // centre
    EXPECT_EQ(pixel(pixels, 20, 44), red);  // inside, near the left edge
    EXPECT_EQ(pixel(pixels, 2, 2), blue);   // corners
    EXPECT_EQ(pixel(pixels, 61, 61), blue);
    EXPECT_EQ(pixel(pixels, 32, 12), blue);  // above the apex
    EXPECT_EQ(pixel(pixels, 12, 44), blue);  // left of the left edge
}

struct DepthTarget {
    vkrc::Image color, depth;
    vkrc::ImageView color_view, depth_view;
    explicit DepthTarget(const vkrc::Device& device)
        : color(attachment_image(device, color_format,
                                 VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT)),
          depth(attachment_image(device, depth_format, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT)),
          color_view(vkrc::ImageView::create(color)),
          depth_view(vkrc::ImageView::create(depth)) {}
};

vkrc::GraphicsPipeline rect_pipeline(const vkrc::Device& device) {
    auto layout = vkrc::PipelineLayout::create(
        device,
        {.push_constant_ranges = {{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(RectPush)}}});
    return vkrc::GraphicsPipelineBuilder(layout)
        .shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::rect_vert))
        .shader(VK_SHADER_STAGE_FRAGMENT_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::push_color_frag))
        .rendering(std::array{color_format}, depth_format)
        .build();
}

// Dynamic rendering into the target: layouts in, begin; end, layout out for the copy.
void begin_target(const vkrc::CommandBuffer& cmd, const DepthTarget& target, VkRenderingFlags flags = 0) {
    const VkImageMemoryBarrier2 in[] = {
        vkrc::image_barrier(target.color.vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                            VK_PIPELINE_STAGE_2_NONE, 0, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                            VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT),
        vkrc::image_barrier(
            target.depth.vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
            VK_PIPELINE_STAGE_2_NONE, 0,
            VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
            VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
            VK_IMAGE_ASPECT_DEPTH_BIT)};
    cmd.pipeline_barrier({}, {}, in);
    vkrc::RenderingAttachment color{.image_view = target.color_view.vk()};
    color.clear_value.color = {{0.0f, 0.0f, 0.0f, 1.0f}};
    vkrc::RenderingAttachment depth{.image_view = target.depth_view.vk(),
                                    .image_layout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                                    .store_op = VK_ATTACHMENT_STORE_OP_DONT_CARE};
    depth.clear_value.depthStencil = {1.0f, 0};
    cmd.begin_rendering({.render_area = {{0, 0}, {size, size}},
                         .color_attachments = std::span(&color, 1),
                         .depth_attachment = &depth,
                         .flags = flags});
}

void end_target(const vkrc::CommandBuffer& cmd, const DepthTarget& target) {
    cmd.end_rendering();
    auto out = vkrc::image_barrier(
        target.color.vk(), VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
        VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
        VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    cmd.pipeline_barrier({}, {}, std::span(&out, 1));
}

void draw_quads(const vkrc::CommandBuffer& cmd, const vkrc::GraphicsPipeline& pipeline,
                std::span<const RectPush> quads) {
    cmd.bind_pipeline(pipeline);
    cmd.set_viewport_and_scissor({size, size});
    for (const auto& q : quads) {
        cmd.push_constants(pipeline.layout(), VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, q);
        cmd.draw(6);
    }
}

void record_quads(const vkrc::CommandBuffer& cmd, const DepthTarget& target, const vkrc::GraphicsPipeline& pipeline,
                  std::span<const RectPush> quads) {
    begin_target(cmd, target);
    draw_quads(cmd, pipeline, quads);
    end_target(cmd, target);
}

// The near quad is drawn first: the far one must lose where they overlap.
constexpr RectPush near_green{{0, 1, 0, 1}, {-0.6f, -0.6f, 0.2f, 0.2f}, 0.3f};
constexpr RectPush far_red{{1, 0, 0, 1}, {-0.2f, -0.2f, 0.6f, 0.6f}, 0.6f};

TEST_F(VulkanTest, DepthTestedQuadsWithDynamicRendering) {
    DepthTarget target(device);
    auto pixels = readback_buffer(device, size * size * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    auto pipeline = rect_pipeline(device);
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    const RectPush quads[] = {near_green, far_red};
    record_quads(cmd, target, pipeline, quads);
    record_readback(cmd, target.color, pixels);
    cmd.end();
    submit_and_wait(queue, cmd);

    EXPECT_EQ(pixel(pixels, 32, 32), green);  // overlap: the near quad wins
    EXPECT_EQ(pixel(pixels, 36, 36), green);
    EXPECT_EQ(pixel(pixels, 19, 19), green);  // near quad only
    EXPECT_EQ(pixel(pixels, 44, 44), red);    // far quad only
    EXPECT_EQ(pixel(pixels, 2, 2), black);    // background
    EXPECT_EQ(pixel(pixels, 60, 4), black);
}

// Two passes into the same colour and depth images, each read back, with
// every barrier from one named use (vkrc/access.hpp) to the next and the
// aspect from the image's format, under synchronization validation: a
// missing or too narrow barrier would be a reported hazard.
void render_through_uses(const vkrc::CommandBuffer& cmd, const DepthTarget& target,
                         const vkrc::GraphicsPipeline& pipeline, const RectPush& quad, const vkrc::Buffer& pixels,
                         vkrc::Use colour_before, vkrc::Use depth_before) {
    namespace use = vkrc::use;
    cmd.pipeline_barrier({}, {},
                         std::array{vkrc::image_barrier(target.color, colour_before, use::colour_attachment_write),
                                    vkrc::image_barrier(target.depth, depth_before, use::depth_attachment)});
    vkrc::RenderingAttachment color{.image_view = target.color_view.vk()};
    color.clear_value.color = {{0.0f, 0.0f, 0.0f, 1.0f}};
    vkrc::RenderingAttachment depth{.image_view = target.depth_view.vk(), .image_layout = use::depth_attachment.layout};
    depth.clear_value.depthStencil = {1.0f, 0};
    cmd.begin_rendering(
        {.render_area = {{0, 0}, {size, size}}, .color_attachments = std::span(&color, 1), .depth_attachment = &depth});
    draw_quads(cmd, pipeline, std::span(&quad, 1));
    cmd.end_rendering();
    const auto to_copy = vkrc::image_barrier(target.color, use::colour_attachment_write, use::transfer_src);
    cmd.pipeline_barrier({}, {}, std::span(&to_copy, 1));
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {size, size, 1};
    cmd.copy_image_to_buffer(target.color, use::transfer_src.layout, pixels, std::span(&region, 1));
    const auto to_host = vkrc::buffer_barrier(pixels, use::transfer_dst, use::host_read);
    cmd.pipeline_barrier({}, std::span(&to_host, 1), {});
}

TEST_F(SyncValidatedTest, TwoPassesThroughNamedUseBarriers) {
    DepthTarget target(device);
    auto first = readback_buffer(device, size * size * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    auto second = readback_buffer(device, size * size * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    auto pipeline = rect_pipeline(device);
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    render_through_uses(cmd, target, pipeline, near_green, first, vkrc::use::none, vkrc::use::none);
    // The second pass overwrites what the copy read, and the depth the first pass wrote.
    render_through_uses(cmd, target, pipeline, far_red, second, vkrc::use::discarded(vkrc::use::transfer_src),
                        vkrc::use::discarded(vkrc::use::depth_attachment));
    cmd.end();
    submit_and_wait(queue, cmd);

    EXPECT_EQ(pixel(first, 19, 19), green);
    EXPECT_EQ(pixel(first, 44, 44), black);
    EXPECT_EQ(pixel(second, 19, 19), black);
    EXPECT_EQ(pixel(second, 44, 44), red);
}

// Everything (buffers, images, views, pipelines, descriptor sets, the command
// buffer) is dropped right after the submit, while a timeline wait that only
// the host releases holds the GPU back. Nothing may be destroyed early (the
// validation layer would report it), and everything is destroyed after.
TEST_F(VulkanTest, DropEverythingRightAfterSubmit) {
    auto gate = vkrc::Semaphore::create_timeline(device, 0);
    auto fence = vkrc::Fence::create(device);
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto survivor = readback_buffer(device, size * size * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    {
        auto storage =
            vkrc::Buffer::create(device, {.size = 4096, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, .memory = {}});
        Fill fill(device, storage);
        DepthTarget target(device);
        auto pipeline = rect_pipeline(device);
        auto cmd = pool.allocate();
        cmd.begin();
        fill.record(cmd, 1024, 7);
        const RectPush quads[] = {near_green, far_red};
        record_quads(cmd, target, pipeline, quads);
        record_readback(cmd, target.color, survivor);
        cmd.end();
        vkrc::SemaphoreSubmit wait{gate, 1};
        vkrc::submit(queue, {.waits = std::span(&wait, 1), .command_buffers = std::span(&cmd, 1)}, fence);
    }
    EXPECT_EQ(pool.pending_free_count(), 1u);
    EXPECT_GT(device.deferred_count(), 10u);
    EXPECT_EQ(fence.status(), VK_NOT_READY);
    gate.signal(1);
    ASSERT_EQ(fence.wait(), VK_SUCCESS);
    EXPECT_EQ(device.deferred_count(), 0u);
    // The work ran with every object intact.
    EXPECT_EQ(pixel(survivor, 32, 32), green);
    EXPECT_EQ(pixel(survivor, 44, 44), red);
    auto next = pool.allocate();  // frees the dropped command buffer
    EXPECT_EQ(pool.pending_free_count(), 0u);
}

// draw_indexed from an index buffer, with vertices that copy_buffer moved
// from an upload buffer into device-local memory.
TEST_F(VulkanTest, IndexedQuadFromCopiedVertices) {
    struct Vertex {
        float position[2];
        float color[3];
    };
    const Vertex vertices[] = {
        {{-0.5f, -0.5f}, {0, 1, 0}}, {{-0.5f, 0.5f}, {0, 1, 0}}, {{0.5f, 0.5f}, {0, 1, 0}}, {{0.5f, -0.5f}, {0, 1, 0}}};
    const std::uint16_t indices[] = {0, 1, 2, 0, 2, 3};
    auto staging = vkrc::Buffer::create(device, {.size = sizeof vertices,
                                                 .usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                                 .memory = {.usage = vkrc::MemoryUsage::upload}});
    staging.allocation().write(0, vertices, 4);
    auto vertex_buffer = vkrc::Buffer::create(
        device,
        {.size = sizeof vertices, .usage = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT});
    auto index_buffer = vkrc::Buffer::create(device, {.size = sizeof indices,
                                                      .usage = VK_BUFFER_USAGE_INDEX_BUFFER_BIT,
                                                      .memory = {.usage = vkrc::MemoryUsage::upload}});
    index_buffer.allocation().write(0, indices, 6);

    DepthTarget target(device);
    auto pixels = readback_buffer(device, size * size * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    auto pipeline =
        vkrc::GraphicsPipelineBuilder(vkrc::PipelineLayout::create(device))
            .shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::triangle_vert))
            .shader(VK_SHADER_STAGE_FRAGMENT_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::triangle_frag))
            .vertex_binding(0, sizeof(Vertex))
            .vertex_attribute(0, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, position))
            .vertex_attribute(1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, color))
            .rendering(std::array{color_format}, depth_format)
            .build();
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    const VkBufferCopy whole{0, 0, sizeof vertices};
    cmd.copy_buffer(staging, vertex_buffer, std::span(&whole, 1));
    auto to_vertex_input =
        vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                             VK_PIPELINE_STAGE_2_VERTEX_ATTRIBUTE_INPUT_BIT, VK_ACCESS_2_VERTEX_ATTRIBUTE_READ_BIT);
    cmd.pipeline_barrier(std::span(&to_vertex_input, 1), {}, {});
    begin_target(cmd, target);
    cmd.bind_pipeline(pipeline);
    cmd.set_viewport_and_scissor({size, size});
    cmd.bind_vertex_buffer(0, vertex_buffer);
    cmd.bind_index_buffer(index_buffer, 0, VK_INDEX_TYPE_UINT16);
    cmd.draw_indexed(6);
    end_target(cmd, target);
    record_readback(cmd, target.color, pixels);
    cmd.end();
    submit_and_wait(queue, cmd);

    EXPECT_EQ(pixel(pixels, 32, 32), green);
    EXPECT_EQ(pixel(pixels, 20, 20), green);  // first triangle
    EXPECT_EQ(pixel(pixels, 44, 20), green);  // second triangle
    EXPECT_EQ(pixel(pixels, 8, 8), black);
    EXPECT_EQ(pixel(pixels, 56, 32), black);
}

// Four threads record one secondary each, from four pools, drawing into one
// quadrant of a dynamic-rendering pass; one primary executes them. Under the
// multi-thread policy each thread also drops its secondary right after the submit.
TEST_F(VulkanTest, SecondariesRecordedOnFourThreadsDrawOneImage) {
    constexpr int threads = 4;
    DepthTarget target(device);
    auto pixels = readback_buffer(device, size * size * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    auto pipeline = rect_pipeline(device);
    const RectPush quads[threads] = {{{1, 0, 0, 1}, {-1, -1, 0, 0}, 0.5f},
                                     {{0, 1, 0, 1}, {0, -1, 1, 0}, 0.5f},
                                     {{0, 0, 1, 1}, {-1, 0, 0, 1}, 0.5f},
                                     {{1, 1, 1, 1}, {0, 0, 1, 1}, 0.5f}};
    std::vector<vkrc::CommandPool> pools;
    for (int t = 0; t < threads; ++t) {
        pools.push_back(vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()}));
    }
    std::vector<vkrc::CommandBuffer> secondaries(threads);
    const VkFormat formats[] = {color_format};
    auto record = [&](int t) {
        auto cmd = pools[t].allocate(VK_COMMAND_BUFFER_LEVEL_SECONDARY);
        cmd.begin_secondary({.color_formats = formats, .depth_format = depth_format});
        draw_quads(cmd, pipeline, std::span(&quads[t], 1));
        cmd.end();
        secondaries[t] = std::move(cmd);
    };
#if VKRC_IS_MULTI_THREAD
    std::vector<std::thread> workers;
    for (int t = 0; t < threads; ++t) workers.emplace_back(record, t);
    for (auto& w : workers) w.join();
#else
    for (int t = 0; t < threads; ++t) record(t);
#endif
    auto primary_pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto primary = primary_pool.allocate();
    primary.begin();
    begin_target(primary, target, VK_RENDERING_CONTENTS_SECONDARY_COMMAND_BUFFERS_BIT);
    primary.execute_commands(secondaries);
    end_target(primary, target);
    record_readback(primary, target.color, pixels);
    primary.end();
    auto fence = vkrc::Fence::create(device);
    vkrc::submit(queue, {.command_buffers = std::span(&primary, 1)}, fence);
#if VKRC_IS_MULTI_THREAD
    std::vector<std::thread> droppers;
    for (int t = 0; t < threads; ++t) droppers.emplace_back([&, t] { secondaries[t].reset(); });
    for (auto& d : droppers) d.join();
#else
    secondaries.clear();
#endif
    ASSERT_EQ(fence.wait(), VK_SUCCESS);
    EXPECT_EQ(pixel(pixels, 16, 16), red);
    EXPECT_EQ(pixel(pixels, 48, 16), green);
    EXPECT_EQ(pixel(pixels, 16, 48), blue);
    EXPECT_EQ(pixel(pixels, 48, 48), (Rgba{255, 255, 255, 255}));
    for (auto& p : pools) {
        auto next = p.allocate(VK_COMMAND_BUFFER_LEVEL_SECONDARY);  // frees the dropped secondary
        EXPECT_EQ(p.pending_free_count(), 0u);
    }
}

}  // namespace
