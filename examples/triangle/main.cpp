// Draws one coloured triangle and saves it as a PNG, without a window:
//     triangle --headless --out triangle.png
// Read top to bottom: device, vertex data, render target, pipeline, commands,
// submission, read-back.
#include <vkrc/vkrc.hpp>

#include "shaders/triangle.frag.h"
#include "shaders/triangle.vert.h"
#include "support/png.hpp"

#include <array>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

namespace {

struct Vertex {
    float position[2];  // normalised device coordinates, y down
    float color[3];
};

constexpr std::uint32_t width = 256, height = 256;
constexpr VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;

int run(const std::string& out_file) {
    // 1. An instance and a device. vkrc picks the best GPU (or lavapipe).
    auto instance = vkrc::Instance::create({.application_name = "vkrc triangle"});
    auto device = vkrc::Device::create(vkrc::PhysicalDevice::select(instance));
    auto queue = device.default_queue();
    std::printf("device: %s\n", device.physical_device().name());

    // 2. Three vertices in a buffer the CPU writes and the GPU reads.
    //    Counter-clockwise on screen, which the pipeline's defaults call front-facing.
    const Vertex vertices[] = {
        {{0.0f, -0.6f}, {1.0f, 0.0f, 0.0f}},   // top: red
        {{-0.6f, 0.6f}, {0.0f, 1.0f, 0.0f}},   // bottom left: green
        {{0.6f, 0.6f}, {0.0f, 0.0f, 1.0f}},    // bottom right: blue
    };
    auto vertex_buffer = vkrc::Buffer::create(
        device, {.size = sizeof vertices, .usage = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT,
                 .memory = {.usage = vkrc::MemoryUsage::upload}});
    vertex_buffer.allocation().write(0, vertices, 3);

    // 3. The image we render into, and a host-visible buffer to copy it to.
    auto image = vkrc::Image::create(
        device, {.format = format, .extent = {width, height, 1},
                 .usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
    auto view = vkrc::ImageView::create(image);
    auto pixels = vkrc::Buffer::create(
        device, {.size = width * height * 4, .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                 .memory = {.usage = vkrc::MemoryUsage::readback}});

    // 4. The pipeline: shaders compiled at build time, the vertex layout, and
    //    dynamic rendering into one colour format. Viewport and scissor are dynamic.
    auto pipeline =
        vkrc::GraphicsPipelineBuilder(vkrc::PipelineLayout::create(device))
            .shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::triangle_vert))
            .shader(VK_SHADER_STAGE_FRAGMENT_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::triangle_frag))
            .vertex_binding(0, sizeof(Vertex))
            .vertex_attribute(0, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, position))
            .vertex_attribute(1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, color))
            .rendering(std::array{format})
            .build();

    // 5. Record: make the image an attachment, clear and draw, then copy it out.
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    auto to_attachment = vkrc::image_barrier(
        image.vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
        VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
    cmd.pipeline_barrier({}, {}, std::span(&to_attachment, 1));

    vkrc::RenderingAttachment target{.image_view = view.vk()};
    target.clear_value.color = {{0.1f, 0.1f, 0.12f, 1.0f}};  // the plain background
    cmd.begin_rendering({.render_area = {{0, 0}, {width, height}}, .color_attachments = std::span(&target, 1)});
    cmd.bind_pipeline(pipeline);
    cmd.set_viewport_and_scissor({width, height});
    cmd.bind_vertex_buffer(0, vertex_buffer);
    cmd.draw(3);
    cmd.end_rendering();

    auto to_copy = vkrc::image_barrier(
        image.vk(), VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
        VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
        VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    cmd.pipeline_barrier({}, {}, std::span(&to_copy, 1));
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {width, height, 1};
    cmd.copy_image_to_buffer(image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, pixels, std::span(&region, 1));
    auto to_host = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                        VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    cmd.end();

    // 6. Submit and wait. A timeout would be a status, not an exception.
    auto done = vkrc::Fence::create(device);
    vkrc::submit(queue, {.command_buffers = std::span(&cmd, 1)}, done);
    if (done.wait() != VK_SUCCESS) return 1;

    // 7. Read the pixels and write the PNG.
    std::vector<std::uint8_t> rgba(width * height * 4);
    pixels.allocation().read(0, std::span(rgba));
    vkrc_examples::write_png(out_file, width, height, rgba);
    std::printf("wrote %s (%ux%u)\n", out_file.c_str(), width, height);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    bool headless = false;
    std::string out_file = "triangle.png";
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--headless") == 0) {
            headless = true;
        } else if (std::strcmp(argv[i], "--out") == 0 && i + 1 < argc) {
            out_file = argv[++i];
        } else {
            std::fprintf(stderr, "usage: %s --headless [--out FILE.png]\n", argv[0]);
            return 2;
        }
    }
    if (!headless) {
        std::fprintf(stderr, "triangle: only --headless is available (windowed mode comes later)\n");
        return 2;
    }
    try {
        return run(out_file);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "triangle: %s\n", e.what());
        return 1;
    }
}
