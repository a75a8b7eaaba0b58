// Records secondary command buffers on several threads and executes them from
// one primary, then checks every pixel on the CPU:
//     threads [--validation]
// The image is a grid of 8x8 coloured cells; each of 4 threads draws two rows
// of it. Built against vkrc::mt, the multi-thread policy: handles may be
// copied and dropped on any thread (atomic counts), and pools and queues lock
// where Vulkan requires it. Recording itself never locks: one pool per thread.
#include <vkrc/vkrc.hpp>

#include "shaders/push_color.frag.h"
#include "shaders/rect.vert.h"

#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <span>
#include <thread>
#include <vector>

namespace {

constexpr std::uint32_t size = 128, cells = 8, cell_px = size / cells, threads = 4;
constexpr VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;

// The push constants of shaders/rect.vert and push_color.frag.
struct Rect {
    float color[4];
    float bounds[4];  // x0 y0 x1 y1 in normalised device coordinates
    float depth;
};

// The colour of cell (x, y), in 0..1.
std::array<float, 3> cell_color(std::uint32_t x, std::uint32_t y) { return {x / 7.0f, y / 7.0f, 1.0f - x / 14.0f}; }

int run(bool validation) {
    // 1. Instance, device, queue.
    auto instance = vkrc::Instance::create({.application_name = "vkrc threads", .validation = validation});
    auto device = vkrc::Device::create(vkrc::PhysicalDevice::select(instance));
    auto queue = device.default_queue();
    std::printf("device: %s\n", device.physical_device().name());

    // 2. A pipeline drawing one rectangle given by push constants, and the target.
    auto layout = vkrc::PipelineLayout::create(
        device,
        {.push_constant_ranges = {{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(Rect)}}});
    auto pipeline =
        vkrc::GraphicsPipelineBuilder(layout)
            .shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::rect_vert))
            .shader(VK_SHADER_STAGE_FRAGMENT_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::push_color_frag))
            .rendering(std::array{format})
            .build();
    auto target =
        vkrc::Image::create(device, {.format = format,
                                     .extent = {size, size, 1},
                                     .usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
    auto target_view = vkrc::ImageView::create(target);

    // 3. Each thread records into a secondary command buffer from its own pool.
    //    The lambda holds copies of the pipeline and layout handles, made here
    //    and dropped on the worker thread: safe with vkrc::mt's atomic counts.
    std::vector<vkrc::CommandBuffer> secondaries(threads);
    std::vector<std::thread> workers;
    const VkFormat formats[] = {format};
    for (std::uint32_t t = 0; t < threads; ++t) {
        auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
        workers.emplace_back([t, pool, pipeline, layout, &formats, &secondaries] {
            auto cmd = pool.allocate(VK_COMMAND_BUFFER_LEVEL_SECONDARY);
            cmd.begin_secondary({.color_formats = formats});  // continues the primary's rendering
            cmd.bind_pipeline(pipeline);
            cmd.set_viewport_and_scissor({size, size});  // dynamic state is not inherited
            for (std::uint32_t y = t * cells / threads; y < (t + 1) * cells / threads; ++y) {
                for (std::uint32_t x = 0; x < cells; ++x) {
                    const auto c = cell_color(x, y);
                    const float x0 = -1.0f + 2.0f * x / cells, y0 = -1.0f + 2.0f * y / cells;
                    const Rect rect{{c[0], c[1], c[2], 1.0f}, {x0, y0, x0 + 2.0f / cells, y0 + 2.0f / cells}, 0.5f};
                    cmd.push_constants(layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, rect);
                    cmd.draw(6);
                }
            }
            cmd.end();
            secondaries[t] = std::move(cmd);  // the command buffer keeps its pool alive
        });
    }
    for (auto& worker : workers) worker.join();

    // 4. The primary begins rendering with contents from secondaries, executes
    //    them in order, and makes the target ready to be copied out.
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto primary = pool.allocate();
    primary.begin();
    auto to_attachment = vkrc::image_barrier(target, vkrc::use::none, vkrc::use::colour_attachment_write);
    primary.pipeline_barrier({}, {}, std::span(&to_attachment, 1));
    vkrc::RenderingAttachment attachment{.image_view = target_view.vk()};
    primary.begin_rendering({.render_area = {{0, 0}, {size, size}},
                             .color_attachments = std::span(&attachment, 1),
                             .flags = VK_RENDERING_CONTENTS_SECONDARY_COMMAND_BUFFERS_BIT});
    primary.execute_commands(secondaries);
    primary.end_rendering();
    auto to_copy = vkrc::image_barrier(target, vkrc::use::colour_attachment_write, vkrc::use::transfer_src);
    primary.pipeline_barrier({}, {}, std::span(&to_copy, 1));
    primary.end();

    // 5. Submit, then drop the secondaries at once: each returns to its pool
    //    only when the GPU has finished this submission.
    auto done = vkrc::Fence::create(device);
    vkrc::submit(queue, {.command_buffers = std::span(&primary, 1)}, done);
    secondaries.clear();
    if (done.wait() != VK_SUCCESS) return 1;

    // 6. Check every pixel against its cell's colour (within 1 of 255 for rounding).
    auto pixels = vkrc::download_image(queue, target, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    std::uint32_t mismatches = 0;
    for (std::uint32_t y = 0; y < size; ++y)
        for (std::uint32_t x = 0; x < size; ++x) {
            const auto c = cell_color(x / cell_px, y / cell_px);
            for (int i = 0; i < 3; ++i)
                mismatches += std::abs(int(pixels[(y * size + x) * 4 + i]) - int(c[i] * 255.0f + 0.5f)) > 1;
        }
    std::printf("%u threads drew %u cells; %u channel mismatches\n", threads, cells * cells, mismatches);
    return mismatches == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
    const bool validation = argc > 1 && std::strcmp(argv[1], "--validation") == 0;
    try {
        return run(validation);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "threads: %s\n", e.what());
        return 1;
    }
}
