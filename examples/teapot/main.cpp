// The teapot benchmark's scene in a resizable window: 25 lit teapots, animated.
//     teapot [--frames N] [--validation]                          a window (closes after N frames)
//     teapot --headless [--frames N] [--validation] [--out teapot.png]
// Read top to bottom: device and presenter, geometry, pipeline, per-frame
// resources, frame loop. The scene (mesh, animation, camera) is bench/teapot/scene.
#include <vkrc/glfw.hpp>
#include <vkrc/vkrc.hpp>

#include "scene/teapot_scene.hpp"
#include "shaders/teapot.frag.h"
#include "shaders/teapot.vert.h"
#include "support/device_buffer.hpp"
#include "support/window_or_headless.hpp"

#include <array>
#include <chrono>
#include <span>
#include <vector>

namespace {

constexpr int teapot_count = 25;
constexpr VkFormat depth_format = VK_FORMAT_D32_SFLOAT;  // every device can render depth into it

int run(const vkrc_examples::WindowOrHeadless& options) {
    // 1. Instance, device and presenter (a window's swapchain or, headless,
    //    a ring of offscreen images), as in examples/triangle.
    vkrc::InstanceCreateInfo instance_info{.application_name = "vkrc teapot", .validation = options.validation};
    vkrc::DeviceRequirements requirements;
    vkrc::glfw::WindowSurface window;
    if (!options.headless) {
        window =
            vkrc::glfw::create_window_surface({.width = 960, .height = 540, .title = "vkrc teapot"}, instance_info);
        requirements.present_surface = window.surface.vk();
        requirements.required_extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
    }
    auto instance = options.headless ? vkrc::Instance::create(instance_info) : window.instance;
    auto device = vkrc::Device::create(vkrc::PhysicalDevice::select(instance, requirements),
                                       {.enabled_extension_names = requirements.required_extensions});
    auto queue = device.default_queue();
    vkrc::Swapchain swapchain;
    vkrc::HeadlessPresenter headless;
    if (options.headless)
        headless = vkrc::HeadlessPresenter::create(queue, {.extent = {480, 270}, .format = VK_FORMAT_R8G8B8A8_UNORM});
    else swapchain = vkrc::Swapchain::create(queue, window.surface);
    vkrc::Presenter& presenter = options.headless ? static_cast<vkrc::Presenter&>(headless) : swapchain;

    // 2. The teapot mesh (Bezier patches, 8x8 quads each), in GPU memory.
    const teapot::Mesh mesh = teapot::tessellate(teapot::newell_teapot(), 8);
    auto positions = vkrc_examples::device_buffer(queue, mesh.positions, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    auto normals = vkrc_examples::device_buffer(queue, mesh.normals, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    auto indices = vkrc_examples::device_buffer(queue, mesh.indices, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);

    // 3. The pipeline: the camera in a uniform buffer (set 0), each teapot's
    //    world matrix and colour in push constants, depth tested.
    auto set_layout = vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT}}});
    auto layout = vkrc::PipelineLayout::create(
        device, {.set_layouts = {set_layout},
                 .push_constant_ranges = {{VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof(teapot::PushConstants)}}});
    auto pipeline =
        vkrc::GraphicsPipelineBuilder(layout)
            .shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::teapot_vert))
            .shader(VK_SHADER_STAGE_FRAGMENT_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::teapot_frag))
            .vertex_binding(0, sizeof(glm::vec3))  // positions
            .vertex_binding(1, sizeof(glm::vec3))  // normals
            .vertex_attribute(0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0)
            .vertex_attribute(1, 1, VK_FORMAT_R32G32B32_SFLOAT, 0)
            .cull_mode(VK_CULL_MODE_NONE)  // the spout and lid openings show inner faces
            .depth_test(true, true, VK_COMPARE_OP_LESS)
            .rendering(std::array{presenter.format()}, depth_format)
            .build();

    // 4. Two frames in flight, each with its command buffer, fence, and
    //    camera uniforms (rewritten every frame: the aspect ratio follows the window).
    struct FrameResources {
        vkrc::CommandBuffer cmd;
        vkrc::Fence done;
        vkrc::Buffer camera;
        vkrc::DescriptorSet set;
    };
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto descriptor_pool =
        vkrc::DescriptorPool::create(device, {.max_sets = 2, .pool_sizes = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 2}}});
    std::array<FrameResources, 2> in_flight;
    for (FrameResources& f : in_flight) {
        f = {pool.allocate(), vkrc::Fence::create(device, true),
             vkrc::Buffer::create(device, {.size = sizeof(teapot::CameraUniforms),
                                           .usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                                           .memory = {.usage = vkrc::MemoryUsage::upload}}),
             descriptor_pool.allocate(set_layout)};
        f.set.write_buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, f.camera);
    }
    // One depth buffer, re-created when the extent changes (the old one is
    // destroyed once the GPU is done with it). Both frames share it: they
    // run in submission order on one queue.
    vkrc::Image depth;
    vkrc::ImageView depth_view;
    VkExtent2D depth_extent{};
    std::array<teapot::PushConstants, teapot_count> draws;

    // 5. The frame loop: acquire, animate, record, submit, present.
    const auto start = std::chrono::steady_clock::now();
    const long frames = options.frame_limit();
    vkrc::Frame frame;  // refilled by every acquire
    for (long n = 0; frames < 0 || n < frames;) {
        if (!options.headless) vkrc::glfw::Window::poll_events();
        if (window.window && window.window.should_close()) break;
        FrameResources& f = in_flight[n % 2];
        f.done.wait();
        presenter.acquire(frame);
        if (!frame) {  // minimised (wait for the window to come back) or being re-created
            if (frame.status == vkrc::PresentStatus::zero_extent) vkrc::glfw::Window::wait_events();
            continue;
        }
        f.done.unsignal();
        if (frame.extent.width != depth_extent.width || frame.extent.height != depth_extent.height) {
            depth = vkrc::Image::create(device, {.format = depth_format,
                                                 .extent = {frame.extent.width, frame.extent.height, 1},
                                                 .usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT});
            depth_view = vkrc::ImageView::create(depth);
            depth_extent = frame.extent;
        }
        // Headless runs use a fixed time step, so that their images are reproducible.
        const double t = options.headless
                             ? n / 60.0
                             : std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        teapot::animate(teapot_count, t, draws);
        f.camera.allocation().write_value(0, teapot::camera(teapot_count, frame.extent.width, frame.extent.height));

        const auto& cmd = f.cmd;
        cmd.begin();
        namespace use = vkrc::use;
        const VkImageMemoryBarrier2 to_attachments[2] = {
            vkrc::image_barrier(frame.image(), use::acquired, use::colour_attachment_write),
            // After the previous frame's depth tests; its depth is not kept.
            vkrc::image_barrier(depth, use::discarded(use::depth_attachment), use::depth_attachment)};
        cmd.pipeline_barrier({}, {}, to_attachments);
        vkrc::RenderingAttachment colour_target{.image_view = frame.view().vk()};
        colour_target.clear_value.color = {{0.08f, 0.09f, 0.11f, 1.0f}};
        vkrc::RenderingAttachment depth_target{depth_view.vk(), use::depth_attachment.layout,
                                               VK_ATTACHMENT_LOAD_OP_CLEAR, VK_ATTACHMENT_STORE_OP_DONT_CARE};
        depth_target.clear_value.depthStencil = {1.0f, 0};
        cmd.begin_rendering({.render_area = {{0, 0}, frame.extent},
                             .color_attachments = std::span(&colour_target, 1),
                             .depth_attachment = &depth_target});
        cmd.bind_pipeline(pipeline);
        cmd.set_viewport_and_scissor(frame.extent);
        cmd.bind_descriptor_set(pipeline, 0, f.set);
        cmd.bind_vertex_buffers(0, std::array{positions.vk(), normals.vk()}, std::array<VkDeviceSize, 2>{0, 0});
        cmd.bind_index_buffer(indices, 0, VK_INDEX_TYPE_UINT16);
        for (const teapot::PushConstants& draw : draws) {  // one draw per teapot
            cmd.push_constants(layout, VK_SHADER_STAGE_VERTEX_BIT, draw);
            cmd.draw_indexed(static_cast<std::uint32_t>(mesh.indices.size()));
        }
        cmd.end_rendering();
        auto to_present =
            vkrc::image_barrier(frame.image(), use::colour_attachment_write, use::presented(frame.present_layout));
        cmd.pipeline_barrier({}, {}, std::span(&to_present, 1));
        cmd.end();
        vkrc::submit(queue, {.waits = frame.waits(), .command_buffers = std::span(&cmd, 1), .signals = frame.signals()},
                     f.done);
        presenter.present(frame);  // a resized window's swapchain is re-created at the next acquire
        ++n;
    }
    device.wait_idle();

    // 6. Headless: read the last image back and write the PNG.
    if (options.headless) vkrc_examples::save_last_frame(headless, options.out_file);
    return 0;
}

}  // namespace

int main(int argc, char** argv) { return vkrc_examples::run_example(argc, argv, "teapot", run); }
