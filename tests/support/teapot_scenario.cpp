#include "teapot_scenario.hpp"

#include "support/vk_test.hpp"

#include "shaders/teapot.frag.h"
#include "shaders/teapot.vert.h"

#include <scene/teapot_scene.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include <array>
#include <span>
#include <vector>

namespace vkrc_test {
namespace {

constexpr std::uint32_t extent = 64;
constexpr VkFormat color_format = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkFormat depth_format = VK_FORMAT_D32_SFLOAT;
constexpr int ring = 2;  // frames in flight

struct Vertex {
    glm::vec3 position;
    glm::vec3 normal;
};
struct Camera {
    glm::mat4 view;
    glm::mat4 proj;
};
struct DrawPush {
    glm::mat4 world;
    glm::vec4 colour;
};

// Tessellated once per process: host data only, no Vulkan.
const teapot::Mesh& mesh() {
    static const teapot::Mesh m = teapot::tessellate(teapot::newell_teapot(), 3);
    return m;
}

struct Target {
    vkrc::Image color, depth;
    vkrc::ImageView color_view, depth_view;
};

}  // namespace

std::vector<std::array<std::uint8_t, 4>> run_teapot_scenario(const vkrc::InstanceCreateInfo& info,
                                                             const TeapotScenarioOptions& options) {
    auto instance = vkrc::Instance::create(info);
    auto physical_device = vkrc::PhysicalDevice::select(instance, test_device_requirements());
    auto device = vkrc::Device::create(physical_device);
    auto queue = device.default_queue();
    const auto& allocator = options.allocator;

    // Mesh buffers, uploaded through staging.
    const auto& m = mesh();
    std::vector<Vertex> vertices(m.positions.size());
    for (std::size_t i = 0; i < vertices.size(); ++i) vertices[i] = {m.positions[i], m.normals[i]};
    auto vertex_buffer =
        vkrc::Buffer::create(device, {.size = vertices.size() * sizeof(Vertex),
                                      .usage = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                      .allocator = allocator});
    vkrc::upload_buffer(queue, vertex_buffer, 0, std::as_bytes(std::span(vertices)));
    auto index_buffer =
        vkrc::Buffer::create(device, {.size = m.indices.size() * sizeof(std::uint16_t),
                                      .usage = VK_BUFFER_USAGE_INDEX_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                      .allocator = allocator});
    vkrc::upload_buffer(queue, index_buffer, 0, std::as_bytes(std::span(m.indices)));

    // One mapped uniform buffer and descriptor set per frame in flight.
    auto set_layout =
        vkrc::DescriptorSetLayout::create(device, {.bindings = {{.binding = 0,
                                                                 .descriptor_type = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER,
                                                                 .stage_flags = VK_SHADER_STAGE_VERTEX_BIT}}});
    auto descriptor_pool = vkrc::DescriptorPool::create(
        device, {.max_sets = ring, .pool_sizes = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, ring}}});
    std::array<vkrc::Buffer, ring> uniforms;
    std::array<vkrc::DescriptorSet, ring> sets;
    for (int i = 0; i < ring; ++i) {
        uniforms[i] = vkrc::Buffer::create(device, {.size = sizeof(Camera),
                                                    .usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                                                    .memory = {.usage = vkrc::MemoryUsage::upload},
                                                    .allocator = allocator});
        sets[i] = descriptor_pool.allocate(set_layout);
        sets[i].write_buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, uniforms[i]);
    }

    auto layout = vkrc::PipelineLayout::create(
        device,
        {.set_layouts = {set_layout}, .push_constant_ranges = {{VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof(DrawPush)}}});
    auto pipeline =
        vkrc::GraphicsPipelineBuilder(layout)
            .shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::teapot_vert))
            .shader(VK_SHADER_STAGE_FRAGMENT_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::teapot_frag))
            .vertex_binding(0, sizeof(Vertex))
            .vertex_attribute(0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position))
            .vertex_attribute(1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, normal))
            .cull_mode(VK_CULL_MODE_NONE)
            .rendering(std::array{color_format}, depth_format)
            .build();

    // The offscreen target ring.
    std::array<Target, ring> targets;
    for (auto& t : targets) {
        t.color =
            vkrc::Image::create(device, {.format = color_format,
                                         .extent = {extent, extent, 1},
                                         .usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                                         .allocator = allocator});
        t.depth = vkrc::Image::create(device, {.format = depth_format,
                                               .extent = {extent, extent, 1},
                                               .usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                                               .allocator = allocator});
        t.color_view = vkrc::ImageView::create(t.color);
        t.depth_view = vkrc::ImageView::create(t.depth);
    }
    auto readback = vkrc::Buffer::create(device, {.size = extent * extent * 4,
                                                  .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                                  .memory = {.usage = vkrc::MemoryUsage::readback},
                                                  .allocator = allocator});

    auto command_pool = vkrc::CommandPool::create(
        device, {.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT, .queue_family_index = queue.family_index()});
    std::array<vkrc::CommandBuffer, ring> cmds;
    std::array<vkrc::Fence, ring> fences;
    for (int i = 0; i < ring; ++i) {
        cmds[i] = command_pool.allocate();
        fences[i] = vkrc::Fence::create(device, true);
    }

    for (int frame = 0; frame < options.frames; ++frame) {
        const int slot = frame % ring;
        const auto& cmd = cmds[slot];
        const auto& target = targets[slot];
        fences[slot].wait();
        fences[slot].unsignal();

        Camera camera{glm::lookAt(glm::vec3(0, -9, 4), glm::vec3(0, 0, 1), glm::vec3(0, 0, 1)),
                      glm::perspective(glm::radians(50.0f), 1.0f, 0.1f, 50.0f)};
        camera.proj[1][1] *= -1;
        uniforms[slot].allocation().write_value(0, camera);

        cmd.begin();
        const VkImageMemoryBarrier2 in[] = {
            vkrc::image_barrier(target.color.vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                VK_PIPELINE_STAGE_2_COPY_BIT, 0, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                                VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT),
            vkrc::image_barrier(
                target.depth.vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT, 0,
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
        cmd.begin_rendering({.render_area = {{0, 0}, {extent, extent}},
                             .color_attachments = std::span(&color, 1),
                             .depth_attachment = &depth});
        cmd.bind_pipeline(pipeline);
        cmd.set_viewport_and_scissor({extent, extent});
        cmd.bind_vertex_buffer(0, vertex_buffer);
        cmd.bind_index_buffer(index_buffer, 0, VK_INDEX_TYPE_UINT16);
        cmd.bind_descriptor_set(pipeline, 0, sets[slot]);
        for (int i = 0; i < 3; ++i) {
            DrawPush push{glm::rotate(glm::translate(glm::mat4(1), glm::vec3(2.5f * (i - 1), 0, 0)),
                                      0.3f * float(frame + i), glm::vec3(0, 0, 1)),
                          glm::vec4(0.3f * float(i), 0.5f, 0.8f, 1.0f)};
            cmd.push_constants(layout, VK_SHADER_STAGE_VERTEX_BIT, push);
            cmd.draw_indexed(static_cast<std::uint32_t>(m.indices.size()));
        }
        cmd.end_rendering();
        const auto out = vkrc::image_barrier(
            target.color.vk(), VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
            VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
            VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
        cmd.pipeline_barrier({}, {}, std::span(&out, 1));
        if (frame == options.frames - 1) {
            VkBufferImageCopy region{};
            region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
            region.imageExtent = {extent, extent, 1};
            cmd.copy_image_to_buffer(target.color, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback,
                                     std::span(&region, 1));
        }
        cmd.end();
        const vkrc::CommandBuffer submitted[] = {cmd};
        vkrc::submit(queue, {.command_buffers = submitted}, fences[slot]);
    }
    for (const auto& f : fences) f.wait();

    std::vector<std::array<std::uint8_t, 4>> pixels(extent * extent);
    readback.allocation().read(0, std::span(pixels));
    return pixels;
}

std::size_t covered_pixels(const std::vector<std::array<std::uint8_t, 4>>& frame) {
    std::size_t covered = 0;
    for (const auto& p : frame) covered += (p[0] | p[1] | p[2]) != 0;
    return covered;
}

}  // namespace vkrc_test
