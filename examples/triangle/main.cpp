// Draws one coloured triangle in a window, or headless into a PNG, with one frame loop:
//     triangle [--frames N] [--validation]                        a window (closes after N frames)
//     triangle --headless [--frames N] [--out triangle.png]
// Read top to bottom: instance and presenter, vertex data, pipeline, frame loop.
#include <vkrc/glfw.hpp>
#include <vkrc/vkrc.hpp>

#include "shaders/triangle.frag.h"
#include "shaders/triangle.vert.h"
#include "support/window_or_headless.hpp"

#include <array>
#include <cstdio>
#include <span>

namespace {

struct Vertex {
    float position[2];  // normalised device coordinates, y down
    float color[3];
};
int run(const vkrc_examples::WindowOrHeadless& options) {
    // 1. An instance, a device and a presenter: a window's swapchain, or a
    //    ring of offscreen images. The rest of the program does not know which.
    vkrc::InstanceCreateInfo instance_info{.application_name = "vkrc triangle", .validation = options.validation};
    vkrc::DeviceRequirements requirements;
    vkrc::glfw::WindowSurface window;
    if (!options.headless) {
        window =
            vkrc::glfw::create_window_surface({.width = 512, .height = 512, .title = "vkrc triangle"}, instance_info);
        requirements.present_surface = window.surface.vk();
        requirements.required_extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
    }
    auto instance = options.headless ? vkrc::Instance::create(instance_info) : window.instance;
    auto device = vkrc::Device::create(vkrc::PhysicalDevice::select(instance, requirements),
                                       {.enabled_extension_names = requirements.required_extensions});
    auto queue = device.default_queue();
    vkrc::Swapchain swapchain;  // one of the two is made
    vkrc::HeadlessPresenter headless;
    if (options.headless)
        headless = vkrc::HeadlessPresenter::create(queue, {.extent = {256, 256}, .format = VK_FORMAT_R8G8B8A8_UNORM});
    else swapchain = vkrc::Swapchain::create(queue, window.surface, {.log = [](const char* m) { std::puts(m); }});
    vkrc::Presenter& presenter = options.headless ? static_cast<vkrc::Presenter&>(headless) : swapchain;

    // 2. Three vertices (red top, green bottom left, blue bottom right) in a buffer
    //    the CPU writes and the GPU reads. Counter-clockwise: front-facing.
    const Vertex vertices[] = {{{0.0f, -0.6f}, {1, 0, 0}}, {{-0.6f, 0.6f}, {0, 1, 0}}, {{0.6f, 0.6f}, {0, 0, 1}}};
    auto vertex_buffer = vkrc::Buffer::create(device, {.size = sizeof vertices,
                                                       .usage = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT,
                                                       .memory = {.usage = vkrc::MemoryUsage::upload}});
    vertex_buffer.allocation().write(0, vertices, 3);

    // 3. The pipeline: shaders compiled at build time, the vertex layout, and
    //    dynamic rendering into the presenter's format. Viewport and scissor are dynamic.
    auto pipeline =
        vkrc::GraphicsPipelineBuilder(vkrc::PipelineLayout::create(device))
            .shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::triangle_vert))
            .shader(VK_SHADER_STAGE_FRAGMENT_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::triangle_frag))
            .vertex_binding(0, sizeof(Vertex))
            .vertex_attribute(0, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, position))
            .vertex_attribute(1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, color))
            .rendering(std::array{presenter.format()})
            .build();

    // 4. Two frames in flight, each with its command buffer and fence.
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    std::array commands{pool.allocate(), pool.allocate()};
    std::array fences{vkrc::Fence::create(device, true), vkrc::Fence::create(device, true)};

    // 5. The frame loop. acquire() re-creates a resized window's swapchain
    //    and returns no image while it is minimised.
    const long frames = options.frame_limit();
    vkrc::Frame frame;  // refilled by every acquire
    for (long n = 0; frames < 0 || n < frames;) {
        if (!options.headless) vkrc::glfw::Window::poll_events();
        if (window.window && window.window.should_close()) break;
        const auto& cmd = commands[n % 2];
        const auto& done = fences[n % 2];
        done.wait();
        presenter.acquire(frame);
        if (!frame) {  // minimised (wait for the window to come back) or being re-created
            if (frame.status == vkrc::PresentStatus::zero_extent) vkrc::glfw::Window::wait_events();
            continue;
        }
        done.unsignal();
        cmd.begin();
        // After the presentation engine is done with it (the acquire semaphore's stage).
        auto to_attachment =
            vkrc::image_barrier(frame.image(), vkrc::use::acquired, vkrc::use::colour_attachment_write);
        cmd.pipeline_barrier({}, {}, std::span(&to_attachment, 1));
        vkrc::RenderingAttachment target{.image_view = frame.view().vk()};
        target.clear_value.color = {{0.1f, 0.1f, 0.12f, 1.0f}};  // the plain background
        cmd.begin_rendering({.render_area = {{0, 0}, frame.extent}, .color_attachments = std::span(&target, 1)});
        cmd.bind_pipeline(pipeline);
        cmd.set_viewport_and_scissor(frame.extent);
        cmd.bind_vertex_buffer(0, vertex_buffer);
        cmd.draw(3);
        cmd.end_rendering();
        auto to_present = vkrc::image_barrier(frame.image(), vkrc::use::colour_attachment_write,
                                              vkrc::use::presented(frame.present_layout));
        cmd.pipeline_barrier({}, {}, std::span(&to_present, 1));
        cmd.end();
        vkrc::submit(queue, {.waits = frame.waits(), .command_buffers = std::span(&cmd, 1), .signals = frame.signals()},
                     done);
        presenter.present(frame);  // a resized window's swapchain is re-created at the next acquire
        ++n;
    }
    device.wait_idle();

    // 6. Headless: read the last image back and write the PNG.
    if (options.headless) vkrc_examples::save_last_frame(headless, options.out_file);
    return 0;
}

}  // namespace

int main(int argc, char** argv) { return vkrc_examples::run_example(argc, argv, "triangle", run); }
