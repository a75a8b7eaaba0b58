// The vkrc variants: the benchmark written as a vkrc user would write it,
// with vkrc's own API for everything, command recording and submission
// included. This file is compiled twice, against vkrc::st and vkrc::mt
// (bench/teapot/CMakeLists.txt); TEAPOT_VKRC_FACTORY names each copy's
// factory, and vkrc's inline namespaces keep the two copies' vkrc symbols
// apart.
//
// Presentation goes through vkrc's presenters in both modes, so headless
// and windowed share one code path: a HeadlessPresenter (headless) or a
// Swapchain on a vkrc::glfw surface (--window), called directly (both are
// final: no virtual call). Per frame they do somewhat more than the
// convention of harness/variant.hpp, being general
// (include/vkrc/swapchain.hpp, src/swapchain.cpp):
//   * both: acquire refills one Frame kept across frames, pointing into the
//     presenter's image set (a reference is taken only when the set changes,
//     so none per frame). The headless presenter's acquire takes a spin lock
//     (an exchange and a store under vkrc-mt, nothing under vkrc-st), makes
//     no Vulkan call and uses no semaphore; its present takes no lock.
//   * Swapchain: its acquire semaphores are a ring of image count + 1 rather
//     than one per frame slot, since the presenter does not see the
//     application's fences; before reusing one, acquire checks that the
//     submission that waited on it has completed (normally already known
//     from this loop's fence waits; otherwise it waits on the queue's
//     timeline). present also takes the queue's mutex (no-op under vkrc-st)
//     and records the queue's last submission number.
#include "harness/thread_pool.hpp"
#include "harness/variant.hpp"
#include "harness/window.hpp"

#include "shaders/teapot.frag.h"
#include "shaders/teapot.vert.h"

#include <vkrc/glfw.hpp>
#include <vkrc/vkrc.hpp>

#include <array>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#ifndef TEAPOT_VKRC_FACTORY
#  error "TEAPOT_VKRC_FACTORY must name this copy's factory (make_vkrc_st_variant or make_vkrc_mt_variant)"
#endif

namespace teapot {
namespace {

class VkrcVariant final : public Variant {
    struct Frame;  // per frame slot, below
public:
    ~VkrcVariant() override {
        // The members release themselves; with the device idle first, each
        // Vulkan object is destroyed as its handle goes (a presented
        // swapchain waits for one empty submission after its last present).
        if (device_) device_.wait_idle();
    }

    void init(const Config& config, const SceneData& scene) override {
        config_ = config;
        recorders_ = config.threads > 1 ? scene.recorders : nullptr;
#if !(defined(VKRC_MULTI_THREAD) && VKRC_MULTI_THREAD)
        // vkrc::st's rule (docs/guide.md, "Thread policies"): all the vkrc
        // objects of one instance on one thread at a time. Each recording
        // thread's reset, begin and end update the device's bookkeeping of
        // open command buffers, which vkrc::st does not lock.
        if (recorders_) throw std::runtime_error("vkrc-st records on one thread only (--threads 1)");
#endif
        draws_.resize(config.teapots);
        index_count_ = static_cast<std::uint32_t>(scene.mesh->indices.size());
        create_device();
        create_presenters();
        create_geometry(*scene.mesh);
        create_depth(to_swapchain_ ? swapchain_.extent() : offscreen_.extent());
        create_pipeline();
        create_frames();
    }

    void acquire() override {
        slot_ = static_cast<std::uint32_t>(frame_count_ % config_.frames_in_flight);
        acquire_frame();
        // Headless the ring keeps its extent (as raw.cpp's, unchecked there).
        if (!frame_ || (to_swapchain_ && (frame_.extent.width > depth_extent_.width ||
                                          frame_.extent.height > depth_extent_.height))) [[unlikely]]
            finish_acquire();
    }

    // Direct calls to the final classes: no virtual call the raw path lacks.
    void acquire_frame() { to_swapchain_ ? swapchain_.acquire(frame_) : offscreen_.acquire(frame_); }

    // Out of the per-frame path (as raw.cpp's re-creation): no image yet, or a
    // re-created swapchain outgrew the depth image (the old one goes after the GPU).
    [[gnu::noinline]] void finish_acquire() {
        while (!frame_) {  // out of date: re-created by the next acquire; zero extent: a minimised window
            if (frame_.status == vkrc::PresentStatus::zero_extent) wait_window_events();
            acquire_frame();
        }
        if (frame_.extent.width > depth_extent_.width || frame_.extent.height > depth_extent_.height)
            create_depth(frame_.extent);
    }

    void uniform() override {
        const std::size_t offset = slot_ * uniform_stride_;
        for (int i = 0; i < config_.uniform_writes; ++i) {
            uniform_writer_.write_value(offset, camera_);
            asm volatile("" ::: "memory");  // as write_camera_uniforms: N writes stay N writes
        }
    }

    void command() override {
        Frame& f = frames_[slot_];
        f.pool.reset_commands();
        const vkrc::CommandBuffer& cmd = f.cmd;
        cmd.begin();
        const bool threaded = !f.secondaries.empty();
        begin_target(cmd, threaded ? VK_RENDERING_CONTENTS_SECONDARY_COMMAND_BUFFERS_BIT : 0);
        if (threaded) record_on_threads(f);
        else record_draws(cmd, f, {0, draws_.size()});
        end_target(cmd);
    }

    // The barriers into the attachment layouts and the rendering's begin.
    void begin_target(vkrc::CommandRecorder cmd, VkRenderingFlags flags) {
        const VkPipelineStageFlags2 depth_stages =
            VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
        const VkImageMemoryBarrier2 to_render[2] = {
            vkrc::image_barrier(frame_.image().vk(), VK_IMAGE_LAYOUT_UNDEFINED,
                                VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, vkrc::Frame::acquire_stage, 0,
                                VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                                VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT),
            vkrc::image_barrier(
                depth_.vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, depth_stages,
                VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, depth_stages,
                VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                VK_IMAGE_ASPECT_DEPTH_BIT)};
        cmd.pipeline_barrier({}, {}, to_render);

        vkrc::RenderingAttachment colour{frame_.view().vk(), VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                         VK_ATTACHMENT_LOAD_OP_CLEAR, VK_ATTACHMENT_STORE_OP_STORE};
        std::memcpy(colour.clear_value.color.float32, clear_colour, sizeof clear_colour);
        vkrc::RenderingAttachment depth{depth_view_.vk(), VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                                        VK_ATTACHMENT_LOAD_OP_CLEAR, VK_ATTACHMENT_STORE_OP_DONT_CARE};
        depth.clear_value.depthStencil = {1.0f, 0};
        cmd.begin_rendering({.render_area = {{0, 0}, frame_.extent},
                             .color_attachments = {&colour, 1},
                             .depth_attachment = &depth,
                             .flags = flags});
    }

    // The state every draw needs, then the draws of range: the whole
    // command stage's draws into the primary, or one thread's slice into its
    // secondary (which inherits no state). Only reads shared members, so
    // that threads may run it at once (no handle is copied). The recorder by
    // value keeps the table and the raw handle in registers across the draws.
    void record_draws(vkrc::CommandRecorder cmd, const Frame& f, DrawRange range) const {
        cmd.bind_pipeline(pipeline_);
        cmd.set_viewport_and_scissor(frame_.extent);
        cmd.bind_descriptor_set(pipeline_, 0, f.set);
        const VkBuffer vertex_buffers[2] = {positions_.vk(), normals_.vk()};
        const VkDeviceSize offsets[2] = {0, 0};
        cmd.bind_vertex_buffers(0, vertex_buffers, offsets);
        cmd.bind_index_buffer(indices_, 0, VK_INDEX_TYPE_UINT16);
        for (std::size_t i = range.first; i < range.last; ++i) {
            cmd.push_constants(layout_, VK_SHADER_STAGE_VERTEX_BIT, draws_[i]);
            cmd.draw_indexed(index_count_);
        }
    }

    // --threads N: thread i records its slice into its own pool's secondary
    // (the pool is used by that thread only, as vkrc::CommandPool requires);
    // the primary executes them in thread order.
    void record_on_threads(const Frame& f) {
        const int threads = int(f.secondaries.size());
        auto record = [&](int i) {
            const vkrc::CommandBuffer& secondary = f.secondaries[std::size_t(i)];
            f.thread_pools[std::size_t(i)].reset_commands();
            secondary.begin_secondary({.color_formats = {&colour_format_, 1}, .depth_format = depth_format});
            record_draws(secondary, f, draw_range(i, threads, draws_.size()));
            secondary.end();
        };
        recorders_->run(record);
        f.cmd.execute_commands(f.secondaries);
    }

    // The rendering's end, the barrier to the presentation layout and the end.
    void end_target(const vkrc::CommandBuffer& cmd) {
        cmd.end_rendering();
        // PRESENT_SRC_KHR for a swapchain, TRANSFER_SRC_OPTIMAL headless.
        const VkImageMemoryBarrier2 to_present =
            vkrc::image_barrier(frame_.image().vk(), VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, frame_.present_layout,
                                VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                                VK_PIPELINE_STAGE_2_NONE, 0);
        cmd.pipeline_barrier({}, {}, {&to_present, 1});
        cmd.end();
    }

    void submit() override {
        Frame& f = frames_[slot_];
        vkrc::submit(queue_, {.waits = frame_.waits(), .command_buffers = {&f.cmd, 1}, .signals = frame_.signals()},
                     f.fence);
        f.submitted = true;
    }

    void present() override {
        // Out of date or suboptimal: the next acquire re-creates the swapchain.
        if (to_swapchain_) swapchain_.present(frame_);
        else offscreen_.present(frame_);
        ++frame_count_;
    }

    void wait() override {
        Frame& next = frames_[frame_count_ % config_.frames_in_flight];
        if (!next.submitted) return;
        next.fence.wait();
        next.fence.unsignal();
        next.submitted = false;
    }

    void update(double t) override { update_scene(config_, t, draws_, camera_); }

    void drain() override { device_.wait_idle(); }

    void render_offscreen(bool on) override { to_swapchain_ = !on && config_.window; }

    // Windowed: one more frame at time t through the window's stages, its
    // swapchain image copied to a readback buffer between its rendering and
    // its presentation (as raw.cpp's read_back_presented_frame): the frame's
    // submission takes the frame's waits, the copy's its signals.
    std::vector<std::uint8_t> read_back_presented_frame(double t) override {
        drain();
        update(t);
        acquire();
        uniform();
        command();
        if (frame_.extent.width != config_.width || frame_.extent.height != config_.height)
            throw std::runtime_error("windowed image check: the swapchain's extent is not --size");
        Frame& f = frames_[slot_];
        vkrc::submit(queue_, {.waits = frame_.waits(), .command_buffers = {&f.cmd, 1}}, f.fence);
        f.fence.wait();
        f.fence.unsignal();
        f.pool.reset_commands();
        const vkrc::CommandBuffer& cmd = f.cmd;
        cmd.begin();
        const VkImage image = frame_.image().vk();
        const VkImageMemoryBarrier2 to_copy = vkrc::image_barrier(
            image, frame_.present_layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
            VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
        cmd.pipeline_barrier({}, {}, {&to_copy, 1});
        VkBufferImageCopy region{};
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.imageExtent = {frame_.extent.width, frame_.extent.height, 1};
        cmd.copy_image_to_buffer(image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback_.vk(), {&region, 1});
        const VkImageMemoryBarrier2 back =
            vkrc::image_barrier(image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, frame_.present_layout,
                                VK_PIPELINE_STAGE_2_COPY_BIT, 0, VK_PIPELINE_STAGE_2_NONE, 0);
        VkBufferMemoryBarrier2 to_host{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2};
        to_host.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
        to_host.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
        to_host.dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT;
        to_host.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT;
        to_host.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        to_host.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        to_host.buffer = readback_.vk();
        to_host.size = VK_WHOLE_SIZE;
        cmd.pipeline_barrier({}, {&to_host, 1}, {&back, 1});
        cmd.end();
        vkrc::submit(queue_, {.command_buffers = {&f.cmd, 1}, .signals = frame_.signals()}, f.fence);
        f.fence.wait();
        f.fence.unsignal();
        std::vector<std::uint8_t> bytes(std::size_t(frame_.extent.width) * frame_.extent.height * 4);
        readback_.allocation().read(0, bytes.data(), bytes.size());
        to_rgba(bytes, colour_format_);
        present();
        wait();
        drain();
        return bytes;
    }

    // Drains, then reads back the headless presenter's last presented image.
    std::vector<std::uint8_t> read_back_offscreen() override {
        drain();
        Frame& f = frames_[slot_];
        if (f.submitted) {
            f.fence.wait();
            f.fence.unsignal();
            f.submitted = false;
        }
        const vkrc::List<std::byte> pixels = offscreen_.read_back(offscreen_.last_presented());
        const auto* bytes = reinterpret_cast<const std::uint8_t*>(pixels.data());
        std::vector<std::uint8_t> image(bytes, bytes + pixels.size());
        to_rgba(image, offscreen_.format());
        return image;
    }

    std::string device_name() const override { return device_.physical_device().name(); }

    const BenchWindow* window() const override { return config_.window ? &window_ : nullptr; }

    std::string presentation() const override {
        if (config_.window)
            return swapchain_presentation(swapchain_.format(), swapchain_.present_mode(), swapchain_.image_count(),
                                          swapchain_.extent());
        return headless_presentation(offscreen_.image_count(), offscreen_.format(), offscreen_.extent());
    }

private:
    struct Frame {
        vkrc::CommandPool pool;
        vkrc::CommandBuffer cmd;
        vkrc::Fence fence;
        vkrc::DescriptorSet set;
        bool submitted = false;
        // --threads N > 1: per thread, a pool and its secondary.
        std::vector<vkrc::CommandPool> thread_pools;
        std::vector<vkrc::CommandBuffer> secondaries;
    };

    void create_device() {
        vkrc::InstanceCreateInfo instance_info;
        instance_info.application_name = "teapot";
        instance_info.validation = config_.validation;
        if (config_.validation) {
            // The harness counts every message and fails the run on any.
            instance_info.debug_callback = [](const vkrc::DebugMessage& m) {
                VkDebugUtilsMessengerCallbackDataEXT data{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CALLBACK_DATA_EXT};
                data.pMessageIdName = m.message_id_name;
                data.pMessage = m.message;
                validation_callback(m.severity, m.types, &data, nullptr);
            };
            instance_info.debug_severities = validation_severities;
        }
        vkrc::DeviceRequirements requirements;
        if (config_.window) {
            window_ = BenchWindow(config_);
            for (const char* name : vkrc::glfw::required_instance_extensions())
                instance_info.enabled_extension_names.push_back(name);
        }
        vkrc::Instance instance = vkrc::Instance::create(instance_info);
        if (config_.window) {
            surface_ = vkrc::glfw::create_surface(instance, window_.get());
            requirements.present_surface = surface_.vk();
            requirements.required_extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
        }
        // A Vulkan 1.3 device with a graphics and compute queue; one queue.
        device_ = vkrc::Device::create(vkrc::PhysicalDevice::select(instance, requirements),
                                       {.enabled_extension_names = requirements.required_extensions});
        queue_ = device_.default_queue();
    }

    // Windowed: the swapchain by the convention's rule, which is vkrc's own
    // rule given these preferences (the requested IMMEDIATE falls back to
    // MAILBOX, then FIFO, as window_present_modes). Both modes: the
    // headless ring, which renders every frame headless and only the
    // reference frame windowed (one image, in the swapchain's format).
    void create_presenters() {
        VkFormat format = colour_format;
        if (config_.window) {
            vkrc::SwapchainCreateInfo info;
            info.preferred_formats = vkrc::List<VkSurfaceFormatKHR>(window_formats, std::size(window_formats));
            info.present_mode = VK_PRESENT_MODE_IMMEDIATE_KHR;
            info.min_image_count = static_cast<std::uint32_t>(config_.frames_in_flight + 1);
            info.extent = {config_.width, config_.height};        // where the surface leaves it to the swapchain
            info.image_usage |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT;  // the image check reads a presented image back
            readback_ = vkrc::Buffer::create(device_, {.size = VkDeviceSize(config_.width) * config_.height * 4,
                                                       .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                                       .memory = {.usage = vkrc::MemoryUsage::readback}});
            swapchain_ = vkrc::Swapchain::create(queue_, surface_, info);
            // vkrc falls back to the surface's first format; the convention has no fallback.
            if (!is_window_format({swapchain_.format(), swapchain_.color_space()})) throw_no_window_format();
            format = swapchain_.format();
        }
        offscreen_ = vkrc::HeadlessPresenter::create(
            queue_, {.extent = {config_.width, config_.height},
                     .format = format,
                     .image_count = static_cast<std::uint32_t>(config_.window ? 1 : config_.frames_in_flight + 1)});
        to_swapchain_ = config_.window;
        colour_format_ = format;
    }

    template <typename T>
    vkrc::Buffer create_vertex_data(const std::vector<T>& data, VkBufferUsageFlags usage) {
        vkrc::Buffer buffer = vkrc::Buffer::create(
            device_, {.size = data.size() * sizeof(T), .usage = usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT});
        vkrc::upload_buffer(queue_, buffer, 0, std::as_bytes(std::span(data)));
        return buffer;
    }

    void create_geometry(const Mesh& mesh) {
        positions_ = create_vertex_data(mesh.positions, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
        normals_ = create_vertex_data(mesh.normals, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
        indices_ = create_vertex_data(mesh.indices, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
        // One region per frame slot in coherent upload memory, device-local
        // where the device has such a type (resizable BAR): the memory type and
        // write strategy of every variant (no flush).
        const VkDeviceSize alignment = device_.physical_device().properties().limits.minUniformBufferOffsetAlignment;
        uniform_stride_ = (sizeof(CameraUniforms) + alignment - 1) / alignment * alignment;
        uniforms_ = vkrc::Buffer::create(device_, {.size = uniform_stride_ * config_.frames_in_flight,
                                                   .usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                                                   .memory = {.usage = vkrc::MemoryUsage::upload,
                                                              .required_flags = VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                                                              .preferred_flags = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT}});
        uniform_writer_ = uniforms_.allocation().write_only();
    }

    // A depth image covering the reference frame and the presenter's images.
    void create_depth(VkExtent2D extent) {
        depth_extent_ = {std::max(config_.width, extent.width), std::max(config_.height, extent.height)};
        depth_ = vkrc::Image::create(device_, {.format = depth_format,
                                               .extent = {depth_extent_.width, depth_extent_.height, 1},
                                               .usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT});
        depth_view_ = vkrc::ImageView::create(depth_);
    }

    void create_pipeline() {
        set_layout_ = vkrc::DescriptorSetLayout::create(
            device_, {.bindings = {{0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT}}});
        layout_ = vkrc::PipelineLayout::create(
            device_, {.set_layouts = {set_layout_},
                      .push_constant_ranges = {{VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof(PushConstants)}}});
        pipeline_ =
            vkrc::GraphicsPipelineBuilder(layout_)
                .shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device_, vkrc_shaders::teapot_vert))
                .shader(VK_SHADER_STAGE_FRAGMENT_BIT, vkrc::ShaderModule::create(device_, vkrc_shaders::teapot_frag))
                .vertex_binding(0, sizeof(glm::vec3))
                .vertex_binding(1, sizeof(glm::vec3))
                .vertex_attribute(0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0)
                .vertex_attribute(1, 1, VK_FORMAT_R32G32B32_SFLOAT, 0)
                .cull_mode(VK_CULL_MODE_NONE)  // the spout and lid openings show inner faces
                .depth_test(true, true, VK_COMPARE_OP_LESS)
                .rendering({&colour_format_, 1}, depth_format)
                .build();
    }

    void create_frames() {
        const auto slots = static_cast<std::uint32_t>(config_.frames_in_flight);
        descriptor_pool_ =
            vkrc::DescriptorPool::create(device_, {.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT,
                                                   .max_sets = slots,
                                                   .pool_sizes = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, slots}}});
        frames_.resize(slots);
        for (std::uint32_t i = 0; i < slots; ++i) {
            Frame& f = frames_[i];
            f.pool = vkrc::CommandPool::create(
                device_, {.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT, .queue_family_index = queue_.family_index()});
            f.cmd = f.pool.allocate();
            f.fence = vkrc::Fence::create(device_);
            f.set = descriptor_pool_.allocate(set_layout_);
            f.set.write_buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, uniforms_, i * uniform_stride_,
                               sizeof(CameraUniforms));
            for (int t = 0; recorders_ && t < recorders_->size(); ++t) {
                f.thread_pools.push_back(vkrc::CommandPool::create(
                    device_,
                    {.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT, .queue_family_index = queue_.family_index()}));
                f.secondaries.push_back(f.thread_pools.back().allocate(VK_COMMAND_BUFFER_LEVEL_SECONDARY));
            }
        }
    }

    Config config_;
    CameraUniforms camera_{};
    std::vector<PushConstants> draws_;
    std::uint32_t index_count_ = 0;
    VkFormat colour_format_ = colour_format;  // the presenter's
    ThreadPool* recorders_ = nullptr;         // --threads N > 1

    BenchWindow window_;  // windowed only; destroyed last, after the surface
    vkrc::Surface surface_;
    vkrc::Device device_;
    vkrc::Queue queue_;
    vkrc::Buffer positions_, normals_, indices_;
    vkrc::Buffer uniforms_;
    vkrc::WriteOnlyView uniform_writer_;
    VkDeviceSize uniform_stride_ = 0;
    vkrc::Buffer readback_;              // windowed: the presented-image check
    vkrc::Swapchain swapchain_;          // windowed
    vkrc::HeadlessPresenter offscreen_;  // headless: every frame; windowed: the reference frame
    bool to_swapchain_ = false;          // frames go to swapchain_, else to offscreen_
    vkrc::Frame frame_;                  // the frame between acquire and the next acquire
    vkrc::Image depth_;
    vkrc::ImageView depth_view_;
    VkExtent2D depth_extent_{};
    vkrc::DescriptorSetLayout set_layout_;
    // Kept as raw C and vk::raii keep theirs (the pipeline keeps it alive
    // too): the draw loop reads its handle from this variant, no pointer
    // chase through the pipeline's state.
    vkrc::PipelineLayout layout_;
    vkrc::GraphicsPipeline pipeline_;
    vkrc::DescriptorPool descriptor_pool_;
    std::vector<Frame> frames_;

    std::uint64_t frame_count_ = 0;
    std::uint32_t slot_ = 0;
};

}  // namespace

std::unique_ptr<Variant> TEAPOT_VKRC_FACTORY() { return std::make_unique<VkrcVariant>(); }

}  // namespace teapot
