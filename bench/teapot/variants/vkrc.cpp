// The vkrc variants: the benchmark written as a vkrc user would write it,
// with vkrc's own API for everything, command recording and submission
// included. This file is compiled twice, against vkrc::st and vkrc::mt
// (bench/teapot/CMakeLists.txt); TEAPOT_VKRC_FACTORY names each copy's
// factory, and vkrc's inline namespaces keep the two copies' vkrc symbols
// apart.
#include "harness/variant.hpp"

#include "shaders/teapot.frag.h"
#include "shaders/teapot.vert.h"

#include <vkrc/vkrc.hpp>

#include <array>
#include <cstdio>
#include <memory>
#include <string>

#ifndef TEAPOT_VKRC_FACTORY
#error "TEAPOT_VKRC_FACTORY must name this copy's factory (make_vkrc_st_variant or make_vkrc_mt_variant)"
#endif

namespace teapot {
namespace {

class VkrcVariant final : public Variant {
public:
    ~VkrcVariant() override {
        // The members release themselves; with the device idle first, each
        // Vulkan object is destroyed as its handle goes (nothing deferred).
        if (device_) device_.wait_idle();
    }

    void init(const Config& config, const SceneData& scene) override {
        config_ = config;
        camera_ = scene.camera;
        draws_.resize(config.teapots);
        index_count_ = static_cast<std::uint32_t>(scene.mesh->indices.size());
        create_device();
        create_geometry(*scene.mesh);
        create_images();
        create_pipeline();
        create_frames();
    }

    void acquire() override {
        slot_ = static_cast<std::uint32_t>(frame_ % frames_.size());
        image_ = acquire_image();
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
        const TargetImage& target = targets_[image_];
        f.pool.reset_commands();
        const vkrc::CommandBuffer& cmd = f.cmd;
        cmd.begin();

        const VkPipelineStageFlags2 depth_stages =
            VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
        const VkImageMemoryBarrier2 to_render[2] = {
            vkrc::image_barrier(target.image.vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                VK_PIPELINE_STAGE_2_NONE, 0, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                                VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT),
            vkrc::image_barrier(depth_.vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                                depth_stages, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, depth_stages,
                                VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                                    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                                VK_IMAGE_ASPECT_DEPTH_BIT)};
        cmd.pipeline_barrier({}, {}, to_render);

        vkrc::RenderingAttachment colour{target.view.vk(), VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                         VK_ATTACHMENT_LOAD_OP_CLEAR, VK_ATTACHMENT_STORE_OP_STORE};
        std::memcpy(colour.clear_value.color.float32, clear_colour, sizeof clear_colour);
        vkrc::RenderingAttachment depth{depth_view_.vk(), VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                                        VK_ATTACHMENT_LOAD_OP_CLEAR, VK_ATTACHMENT_STORE_OP_DONT_CARE};
        depth.clear_value.depthStencil = {1.0f, 0};
        cmd.begin_rendering({.render_area = {{0, 0}, extent_},
                             .color_attachments = {&colour, 1},
                             .depth_attachment = &depth});

        cmd.bind_pipeline(pipeline_);
        cmd.set_viewport_and_scissor(extent_);
        cmd.bind_descriptor_set(pipeline_, 0, f.set);
        const VkBuffer vertex_buffers[2] = {positions_.vk(), normals_.vk()};
        const VkDeviceSize offsets[2] = {0, 0};
        cmd.bind_vertex_buffers(0, vertex_buffers, offsets);
        cmd.bind_index_buffer(indices_, 0, VK_INDEX_TYPE_UINT16);
        const vkrc::PipelineLayout& layout = pipeline_.layout();
        for (const PushConstants& d : draws_) {
            cmd.push_constants(layout, VK_SHADER_STAGE_VERTEX_BIT, d);
            cmd.draw_indexed(index_count_);
        }
        cmd.end_rendering();

        // Where a swapchain's image would go to PRESENT_SRC_KHR.
        const VkImageMemoryBarrier2 to_present = vkrc::image_barrier(
            target.image.vk(), VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
            VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
            VK_PIPELINE_STAGE_2_NONE, 0);
        cmd.pipeline_barrier({}, {}, {&to_present, 1});
        cmd.end();
    }

    void submit() override {
        Frame& f = frames_[slot_];
        vkrc::submit(queue_, {.command_buffers = {&f.cmd, 1}}, f.fence);
        f.submitted = true;
    }

    void present() override {
        present_image(image_);
        ++frame_;
    }

    void wait() override {
        Frame& next = frames_[frame_ % frames_.size()];
        if (!next.submitted) return;
        next.fence.wait();
        next.fence.unsignal();
        next.submitted = false;
    }

    void update(double t) override { animate(config_.teapots, t, draws_); }

    void drain() override { device_.wait_idle(); }

    std::vector<std::uint8_t> render_reference_frame(double t) override {
        drain();
        update(t);
        acquire();
        uniform();
        command();
        submit();
        present();
        drain();
        Frame& f = frames_[slot_];
        f.fence.wait();
        f.fence.unsignal();
        f.submitted = false;
        const std::vector<std::byte> pixels =
            vkrc::download_image(queue_, targets_[presented_image_].image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
        const auto* bytes = reinterpret_cast<const std::uint8_t*>(pixels.data());
        return {bytes, bytes + pixels.size()};
    }

    std::string device_name() const override { return device_.physical_device().name(); }

private:
    // A stand-in for a swapchain image: the image and its attachment view.
    struct TargetImage {
        vkrc::Image image;
        vkrc::ImageView view;
    };
    struct Frame {
        vkrc::CommandPool pool;
        vkrc::CommandBuffer cmd;
        vkrc::Fence fence;
        vkrc::DescriptorSet set;
        bool submitted = false;
    };

    // The headless presenter (harness/variant.hpp): the ring image of this
    // frame, and handing it over. Bookkeeping only; a swapchain presenter
    // replaces these two.
    std::uint32_t acquire_image() const { return static_cast<std::uint32_t>(frame_ % targets_.size()); }
    void present_image(std::uint32_t image) { presented_image_ = image; }

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
        vkrc::Instance instance = vkrc::Instance::create(instance_info);
        // A Vulkan 1.3 device with a graphics and compute queue; one queue.
        device_ = vkrc::Device::create(vkrc::PhysicalDevice::select(instance));
        queue_ = device_.default_queue();
        extent_ = {config_.width, config_.height};
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
        uniforms_ = vkrc::Buffer::create(
            device_, {.size = uniform_stride_ * config_.frames_in_flight,
                      .usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                      .memory = {.usage = vkrc::MemoryUsage::upload,
                                 .required_flags = VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                                 .preferred_flags = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT}});
        uniform_writer_ = uniforms_.allocation().write_only();
    }

    vkrc::Image create_image(VkFormat format, VkImageUsageFlags usage) {
        return vkrc::Image::create(device_, {.format = format,
                                             .extent = {config_.width, config_.height, 1},
                                             .usage = usage});
    }

    void create_images() {
        targets_.resize(config_.frames_in_flight + 1);
        for (TargetImage& target : targets_) {
            target.image = create_image(colour_format,
                                        VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
            target.view = vkrc::ImageView::create(target.image);
        }
        depth_ = create_image(depth_format, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT);
        depth_view_ = vkrc::ImageView::create(depth_);
    }

    void create_pipeline() {
        set_layout_ = vkrc::DescriptorSetLayout::create(
            device_, {.bindings = {{0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT}}});
        vkrc::PipelineLayout layout = vkrc::PipelineLayout::create(
            device_, {.set_layouts = {set_layout_},
                      .push_constant_ranges = {{VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof(PushConstants)}}});
        pipeline_ = vkrc::GraphicsPipelineBuilder(layout)
                        .shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device_, vkrc_shaders::teapot_vert))
                        .shader(VK_SHADER_STAGE_FRAGMENT_BIT,
                                vkrc::ShaderModule::create(device_, vkrc_shaders::teapot_frag))
                        .vertex_binding(0, sizeof(glm::vec3))
                        .vertex_binding(1, sizeof(glm::vec3))
                        .vertex_attribute(0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0)
                        .vertex_attribute(1, 1, VK_FORMAT_R32G32B32_SFLOAT, 0)
                        .cull_mode(VK_CULL_MODE_NONE)  // the spout and lid openings show inner faces
                        .depth_test(true, true, VK_COMPARE_OP_LESS)
                        .rendering({&colour_format, 1}, depth_format)
                        .build();
    }

    void create_frames() {
        const auto slots = static_cast<std::uint32_t>(config_.frames_in_flight);
        descriptor_pool_ = vkrc::DescriptorPool::create(
            device_, {.flags = 0, .max_sets = slots, .pool_sizes = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, slots}}});
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
        }
    }

    Config config_;
    CameraUniforms camera_{};
    std::vector<PushConstants> draws_;
    std::uint32_t index_count_ = 0;
    VkExtent2D extent_{};

    vkrc::Device device_;
    vkrc::Queue queue_;
    vkrc::Buffer positions_, normals_, indices_;
    vkrc::Buffer uniforms_;
    vkrc::WriteOnlyView uniform_writer_;
    VkDeviceSize uniform_stride_ = 0;
    std::vector<TargetImage> targets_;
    vkrc::Image depth_;
    vkrc::ImageView depth_view_;
    vkrc::DescriptorSetLayout set_layout_;
    vkrc::GraphicsPipeline pipeline_;
    vkrc::DescriptorPool descriptor_pool_;
    std::vector<Frame> frames_;

    std::uint64_t frame_ = 0;
    std::uint32_t slot_ = 0;
    std::uint32_t image_ = 0;
    std::uint32_t presented_image_ = 0;
};

}  // namespace

std::unique_ptr<Variant> TEAPOT_VKRC_FACTORY() { return std::make_unique<VkrcVariant>(); }

}  // namespace teapot
