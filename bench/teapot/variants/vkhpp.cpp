// The Vulkan-Hpp variant: vk::raii from Debian's headers, written the way
// its samples do (its own translation unit: the header compiles slowly).
// Windowed (--window), it presents through vk::raii::SurfaceKHR/SwapchainKHR.
#include "harness/thread_pool.hpp"
#include "harness/variant.hpp"
#include "harness/window.hpp"

#include "shaders/teapot.frag.h"
#include "shaders/teapot.vert.h"

#include <vulkan/vulkan_raii.hpp>

#define GLFW_INCLUDE_NONE  // Vulkan only, no OpenGL headers
#include <GLFW/glfw3.h>

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

namespace teapot {
namespace {

class VkhppVariant final : public Variant {
    struct Frame;  // per frame slot, below
public:
    ~VkhppVariant() override {
        if (device_) device_->waitIdle();
    }

    void init(const Config& config, const SceneData& scene) override {
        config_ = config;
        recorders_ = config.threads > 1 ? scene.recorders : nullptr;
        draws_.resize(config.teapots);
        index_count_ = static_cast<std::uint32_t>(scene.mesh->indices.size());
        present_to_window_ = config.window;
        create_instance();
        create_device();
        if (config.window) create_swapchain();
        create_geometry(*scene.mesh);
        create_images();
        create_pipeline();
        create_frames();
    }

    void acquire() override {
        slot_ = static_cast<std::uint32_t>(frame_ % config_.frames_in_flight);
        if (!present_to_window_) {
            image_ = static_cast<std::uint32_t>(frame_ % ring_.size());
            target_ = {*ring_[image_].image, *ring_[image_].view, vk::Extent2D(config_.width, config_.height),
                       vk::ImageLayout::eTransferSrcOptimal};
            return;
        }
        for (;;) {
            if (swapchain_stale_) recreate_swapchain();
            try {
                auto [result, index] = swapchain_.acquireNextImage(UINT64_MAX, *frames_[slot_].acquire_semaphore);
                if (result == vk::Result::eSuboptimalKHR)
                    swapchain_stale_ = true;  // usable; re-created after its present
                image_ = index;
                break;
            } catch (const vk::OutOfDateKHRError&) {
                swapchain_stale_ = true;
            }
        }
        target_ = {swapchain_images_[image_], *swapchain_views_[image_], swapchain_extent_,
                   vk::ImageLayout::ePresentSrcKHR};
    }

    void uniform() override {
        write_camera_uniforms(static_cast<char*>(uniform_mapped_) + slot_ * uniform_stride_, camera_,
                              config_.uniform_writes);
    }

    void command() override {
        Frame& f = frames_[slot_];
        f.pool.reset();
        const vk::raii::CommandBuffer& cmd = f.cmd;
        cmd.begin({vk::CommandBufferUsageFlagBits::eOneTimeSubmit});
        const bool threaded = !f.secondaries.empty();
        begin_target(cmd, threaded ? vk::RenderingFlagBits::eContentsSecondaryCommandBuffers : vk::RenderingFlags{});
        if (threaded) record_on_threads(f);
        else record_draws(cmd, f, {0, draws_.size()});
        end_target(cmd);
    }

    // The barriers into the attachment layouts and the rendering's begin.
    void begin_target(const vk::raii::CommandBuffer& cmd, vk::RenderingFlags flags) const {
        std::array<vk::ImageMemoryBarrier2, 2> to_render{
            vk::ImageMemoryBarrier2(
                vk::PipelineStageFlagBits2::eColorAttachmentOutput, {},
                vk::PipelineStageFlagBits2::eColorAttachmentOutput, vk::AccessFlagBits2::eColorAttachmentWrite,
                vk::ImageLayout::eUndefined, vk::ImageLayout::eColorAttachmentOptimal, VK_QUEUE_FAMILY_IGNORED,
                VK_QUEUE_FAMILY_IGNORED, target_.image, {vk::ImageAspectFlagBits::eColor, 0, 1, 0, 1}),
            vk::ImageMemoryBarrier2(
                vk::PipelineStageFlagBits2::eEarlyFragmentTests | vk::PipelineStageFlagBits2::eLateFragmentTests,
                vk::AccessFlagBits2::eDepthStencilAttachmentWrite,
                vk::PipelineStageFlagBits2::eEarlyFragmentTests | vk::PipelineStageFlagBits2::eLateFragmentTests,
                vk::AccessFlagBits2::eDepthStencilAttachmentRead | vk::AccessFlagBits2::eDepthStencilAttachmentWrite,
                vk::ImageLayout::eUndefined, vk::ImageLayout::eDepthAttachmentOptimal, VK_QUEUE_FAMILY_IGNORED,
                VK_QUEUE_FAMILY_IGNORED, *depth_.image, {vk::ImageAspectFlagBits::eDepth, 0, 1, 0, 1})};
        cmd.pipelineBarrier2(vk::DependencyInfo({}, {}, {}, to_render));

        vk::RenderingAttachmentInfo colour(target_.view, vk::ImageLayout::eColorAttachmentOptimal, {}, {}, {},
                                           vk::AttachmentLoadOp::eClear, vk::AttachmentStoreOp::eStore,
                                           vk::ClearColorValue(std::array<float, 4>{clear_colour[0], clear_colour[1],
                                                                                    clear_colour[2], clear_colour[3]}));
        vk::RenderingAttachmentInfo depth(*depth_.view, vk::ImageLayout::eDepthAttachmentOptimal, {}, {}, {},
                                          vk::AttachmentLoadOp::eClear, vk::AttachmentStoreOp::eDontCare,
                                          vk::ClearDepthStencilValue(1.0f, 0));
        cmd.beginRendering(vk::RenderingInfo(flags, {{0, 0}, target_.extent}, 1, 0, colour, &depth));
    }

    // The state every draw needs, then the draws of range: into the primary,
    // or one thread's slice into its secondary (which inherits no state).
    void record_draws(const vk::raii::CommandBuffer& cmd, const Frame& f, DrawRange range) const {
        cmd.bindPipeline(vk::PipelineBindPoint::eGraphics, *pipeline_);
        cmd.setViewport(0, vk::Viewport(0, 0, float(target_.extent.width), float(target_.extent.height), 0, 1));
        cmd.setScissor(0, vk::Rect2D({0, 0}, target_.extent));
        cmd.bindDescriptorSets(vk::PipelineBindPoint::eGraphics, *pipeline_layout_, 0, *f.descriptor_set, {});
        cmd.bindVertexBuffers(0, {*positions_.buffer, *normals_.buffer}, {0, 0});
        cmd.bindIndexBuffer(*indices_.buffer, 0, vk::IndexType::eUint16);
        for (std::size_t i = range.first; i < range.last; ++i) {
            cmd.pushConstants<PushConstants>(*pipeline_layout_, vk::ShaderStageFlagBits::eVertex, 0, draws_[i]);
            cmd.drawIndexed(index_count_, 1, 0, 0, 0);
        }
    }

    // --threads N: thread i records its slice into the secondary of its own
    // pool; the primary executes them in thread order.
    void record_on_threads(const Frame& f) const {
        const int threads = int(f.secondaries.size());
        auto record = [&](int i) {
            const auto t = std::size_t(i);
            f.thread_pools[t].reset();
            const vk::raii::CommandBuffer& secondary = f.secondaries[t];
            const vk::Format format = colour_format_;
            vk::StructureChain<vk::CommandBufferInheritanceInfo, vk::CommandBufferInheritanceRenderingInfo> inheritance(
                vk::CommandBufferInheritanceInfo(),
                vk::CommandBufferInheritanceRenderingInfo({}, 0, format, vk::Format(depth_format), {},
                                                          vk::SampleCountFlagBits::e1));
            secondary.begin(vk::CommandBufferBeginInfo(
                vk::CommandBufferUsageFlagBits::eOneTimeSubmit | vk::CommandBufferUsageFlagBits::eRenderPassContinue,
                &inheritance.get<vk::CommandBufferInheritanceInfo>()));
            record_draws(secondary, f, draw_range(i, threads, draws_.size()));
            secondary.end();
        };
        recorders_->run(record);
        f.cmd.executeCommands(f.secondary_handles);
    }

    // The rendering's end, the barrier to the presentation layout and the end.
    void end_target(const vk::raii::CommandBuffer& cmd) const {
        cmd.endRendering();
        vk::ImageMemoryBarrier2 to_present(
            vk::PipelineStageFlagBits2::eColorAttachmentOutput, vk::AccessFlagBits2::eColorAttachmentWrite,
            vk::PipelineStageFlagBits2::eNone, {}, vk::ImageLayout::eColorAttachmentOptimal, target_.present_layout,
            VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED, target_.image,
            {vk::ImageAspectFlagBits::eColor, 0, 1, 0, 1});
        cmd.pipelineBarrier2(vk::DependencyInfo({}, {}, {}, to_present));
        cmd.end();
    }

    void submit() override {
        Frame& f = frames_[slot_];
        vk::CommandBufferSubmitInfo cmd_info(*f.cmd);
        if (present_to_window_) {
            vk::SemaphoreSubmitInfo wait(*f.acquire_semaphore, 0, vk::PipelineStageFlagBits2::eColorAttachmentOutput);
            vk::SemaphoreSubmitInfo signal(*render_done_[image_], 0, vk::PipelineStageFlagBits2::eAllCommands);
            queue_->submit2(vk::SubmitInfo2({}, wait, cmd_info, signal), *f.fence);
        } else {
            queue_->submit2(vk::SubmitInfo2({}, {}, cmd_info, {}), *f.fence);
        }
        f.submitted = true;
    }

    void present() override {
        if (present_to_window_) {
            try {
                if (queue_->presentKHR(vk::PresentInfoKHR(*render_done_[image_], *swapchain_, image_)) ==
                    vk::Result::eSuboptimalKHR)
                    swapchain_stale_ = true;  // re-created at the next acquire
            } catch (const vk::OutOfDateKHRError&) {
                swapchain_stale_ = true;
            }
        }
        presented_image_ = image_;
        ++frame_;
    }

    void wait() override {
        Frame& next = frames_[frame_ % config_.frames_in_flight];
        if (!next.submitted) return;
        if (device_->waitForFences(*next.fence, VK_TRUE, UINT64_MAX) != vk::Result::eSuccess)
            throw std::runtime_error("vkWaitForFences timed out");
        device_->resetFences(*next.fence);
        next.submitted = false;
    }

    void update(double t) override { update_scene(config_, t, draws_, camera_); }

    void drain() override { device_->waitIdle(); }

    void render_offscreen(bool on) override { present_to_window_ = !on && config_.window; }

    // Windowed: one more frame at time t through the window's stages, its
    // swapchain image copied to the readback buffer between its rendering and
    // its presentation (as raw.cpp's read_back_presented_frame).
    std::vector<std::uint8_t> read_back_presented_frame(double t) override {
        drain();
        update(t);
        acquire();
        uniform();
        command();
        if (swapchain_extent_.width != config_.width || swapchain_extent_.height != config_.height)
            throw std::runtime_error("windowed image check: the swapchain's extent is not --size");
        Frame& f = frames_[slot_];
        vk::CommandBufferSubmitInfo cmd_info(*f.cmd);
        vk::SemaphoreSubmitInfo wait(*f.acquire_semaphore, 0, vk::PipelineStageFlagBits2::eColorAttachmentOutput);
        queue_->submit2(vk::SubmitInfo2({}, wait, cmd_info, {}), *f.fence);
        (void)device_->waitForFences(*f.fence, VK_TRUE, UINT64_MAX);
        device_->resetFences(*f.fence);
        f.pool.reset();
        const vk::raii::CommandBuffer& cmd = f.cmd;
        cmd.begin({vk::CommandBufferUsageFlagBits::eOneTimeSubmit});
        const vk::Image image = swapchain_images_[image_];
        vk::ImageMemoryBarrier2 to_copy(vk::PipelineStageFlagBits2::eNone, {}, vk::PipelineStageFlagBits2::eCopy,
                                        vk::AccessFlagBits2::eTransferRead, vk::ImageLayout::ePresentSrcKHR,
                                        vk::ImageLayout::eTransferSrcOptimal, VK_QUEUE_FAMILY_IGNORED,
                                        VK_QUEUE_FAMILY_IGNORED, image, {vk::ImageAspectFlagBits::eColor, 0, 1, 0, 1});
        cmd.pipelineBarrier2(vk::DependencyInfo({}, {}, {}, to_copy));
        vk::BufferImageCopy region(0, 0, 0, {vk::ImageAspectFlagBits::eColor, 0, 0, 1}, {0, 0, 0},
                                   {swapchain_extent_.width, swapchain_extent_.height, 1});
        cmd.copyImageToBuffer(image, vk::ImageLayout::eTransferSrcOptimal, *readback_.buffer, region);
        vk::ImageMemoryBarrier2 back(vk::PipelineStageFlagBits2::eCopy, {}, vk::PipelineStageFlagBits2::eNone, {},
                                     vk::ImageLayout::eTransferSrcOptimal, vk::ImageLayout::ePresentSrcKHR,
                                     VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED, image,
                                     {vk::ImageAspectFlagBits::eColor, 0, 1, 0, 1});
        vk::BufferMemoryBarrier2 to_host(vk::PipelineStageFlagBits2::eCopy, vk::AccessFlagBits2::eTransferWrite,
                                         vk::PipelineStageFlagBits2::eHost, vk::AccessFlagBits2::eHostRead,
                                         VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED, *readback_.buffer, 0,
                                         VK_WHOLE_SIZE);
        cmd.pipelineBarrier2(vk::DependencyInfo({}, {}, to_host, back));
        cmd.end();
        vk::SemaphoreSubmitInfo signal(*render_done_[image_], 0, vk::PipelineStageFlagBits2::eAllCommands);
        queue_->submit2(vk::SubmitInfo2({}, {}, cmd_info, signal), *f.fence);
        (void)device_->waitForFences(*f.fence, VK_TRUE, UINT64_MAX);
        device_->resetFences(*f.fence);
        const auto* pixels = static_cast<const std::uint8_t*>(readback_.mapped);
        std::vector<std::uint8_t> bytes(pixels,
                                        pixels + std::size_t(swapchain_extent_.width) * swapchain_extent_.height * 4);
        to_rgba(bytes, VkFormat(colour_format_));
        present();
        this->wait();
        drain();
        return bytes;
    }

    // Drains, then copies the ring image last presented to the readback
    // buffer with a one-off command buffer from the last frame's slot.
    std::vector<std::uint8_t> read_back_offscreen() override {
        drain();
        Frame& f = frames_[slot_];
        if (f.submitted) {
            (void)device_->waitForFences(*f.fence, VK_TRUE, UINT64_MAX);
            device_->resetFences(*f.fence);
            f.submitted = false;
        }
        f.pool.reset();
        const vk::raii::CommandBuffer& cmd = f.cmd;
        cmd.begin({vk::CommandBufferUsageFlagBits::eOneTimeSubmit});
        vk::ImageMemoryBarrier2 to_copy(
            vk::PipelineStageFlagBits2::eColorAttachmentOutput, vk::AccessFlagBits2::eColorAttachmentWrite,
            vk::PipelineStageFlagBits2::eCopy, vk::AccessFlagBits2::eTransferRead, vk::ImageLayout::eTransferSrcOptimal,
            vk::ImageLayout::eTransferSrcOptimal, VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED,
            *ring_[presented_image_].image, {vk::ImageAspectFlagBits::eColor, 0, 1, 0, 1});
        cmd.pipelineBarrier2(vk::DependencyInfo({}, {}, {}, to_copy));
        vk::BufferImageCopy region(0, 0, 0, {vk::ImageAspectFlagBits::eColor, 0, 0, 1}, {0, 0, 0},
                                   {config_.width, config_.height, 1});
        cmd.copyImageToBuffer(*ring_[presented_image_].image, vk::ImageLayout::eTransferSrcOptimal, *readback_.buffer,
                              region);
        vk::BufferMemoryBarrier2 to_host(vk::PipelineStageFlagBits2::eCopy, vk::AccessFlagBits2::eTransferWrite,
                                         vk::PipelineStageFlagBits2::eHost, vk::AccessFlagBits2::eHostRead,
                                         VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED, *readback_.buffer, 0,
                                         VK_WHOLE_SIZE);
        cmd.pipelineBarrier2(vk::DependencyInfo({}, {}, to_host, {}));
        cmd.end();
        vk::CommandBufferSubmitInfo cmd_info(*cmd);
        queue_->submit2(vk::SubmitInfo2({}, {}, cmd_info, {}), *f.fence);
        (void)device_->waitForFences(*f.fence, VK_TRUE, UINT64_MAX);
        device_->resetFences(*f.fence);
        const auto* pixels = static_cast<const std::uint8_t*>(readback_.mapped);
        std::vector<std::uint8_t> image(pixels, pixels + std::size_t(config_.width) * config_.height * 4);
        to_rgba(image, VkFormat(colour_format_));
        return image;
    }

    std::string device_name() const override { return device_name_; }

    const BenchWindow* window() const override { return config_.window ? &window_ : nullptr; }

    std::string presentation() const override {
        return config_.window
                   ? swapchain_presentation(VkFormat(colour_format_), VkPresentModeKHR(present_mode_),
                                            swapchain_images_.size(), swapchain_extent_)
                   : headless_presentation(ring_.size(), VkFormat(colour_format_), {config_.width, config_.height});
    }

private:
    struct Buffer {
        vk::raii::Buffer buffer = nullptr;
        vk::raii::DeviceMemory memory = nullptr;
        void* mapped = nullptr;
    };
    struct Image {
        vk::raii::Image image = nullptr;
        vk::raii::DeviceMemory memory = nullptr;
        vk::raii::ImageView view = nullptr;
    };
    struct Frame {
        vk::raii::CommandPool pool = nullptr;
        vk::raii::CommandBuffer cmd = nullptr;
        vk::raii::Fence fence = nullptr;
        vk::raii::DescriptorSet descriptor_set = nullptr;
        vk::raii::Semaphore acquire_semaphore = nullptr;  // windowed only
        bool submitted = false;
        // --threads N > 1: per thread, a pool and its secondary (and the
        // secondaries' handles, as vkCmdExecuteCommands takes them).
        std::vector<vk::raii::CommandPool> thread_pools;
        std::vector<vk::raii::CommandBuffer> secondaries;
        std::vector<vk::CommandBuffer> secondary_handles;
    };
    // What this frame renders into: a ring image or a swapchain image.
    struct Target {
        vk::Image image;
        vk::ImageView view;
        vk::Extent2D extent;
        vk::ImageLayout present_layout = vk::ImageLayout::eUndefined;
    };

    void create_instance() {
        vk::ApplicationInfo app("teapot", 1, nullptr, 0, VK_API_VERSION_1_3);
        vk::DebugUtilsMessengerCreateInfoEXT messenger(
            {}, vk::DebugUtilsMessageSeverityFlagsEXT(validation_severities),
            vk::DebugUtilsMessageTypeFlagsEXT(validation_types),
            reinterpret_cast<PFN_vkDebugUtilsMessengerCallbackEXT>(&validation_callback));
        std::vector<const char*> layers, extensions;
        if (config_.window) {
            window_ = BenchWindow(config_);
            extensions = window_instance_extensions();
        }
        if (config_.validation) {
            layers.push_back(validation_layer);
            extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        }
        vk::InstanceCreateInfo info({}, &app, layers, extensions);
        if (config_.validation) info.pNext = &messenger;
        instance_.emplace(context_, info);
        if (config_.validation) messenger_.emplace(*instance_, messenger);
        if (config_.window) {
            VkSurfaceKHR surface = VK_NULL_HANDLE;
            vk::resultCheck(vk::Result(glfwCreateWindowSurface(**instance_, window_.get(), nullptr, &surface)),
                            "glfwCreateWindowSurface");
            surface_.emplace(*instance_, surface);
        }
    }

    void create_device() {
        vk::raii::PhysicalDevices devices(*instance_);
        for (auto& candidate : devices) {
            vk::PhysicalDeviceProperties properties = candidate.getProperties();
            if (properties.apiVersion < VK_API_VERSION_1_3) continue;
            auto families = candidate.getQueueFamilyProperties();
            for (std::uint32_t i = 0; i < families.size(); ++i)
                if ((families[i].queueFlags & vk::QueueFlagBits::eGraphics) &&
                    (!config_.window || candidate.getSurfaceSupportKHR(i, **surface_))) {
                    physical_device_.emplace(std::move(candidate));
                    queue_family_ = i;
                    device_name_ = properties.deviceName.data();
                    uniform_alignment_ = properties.limits.minUniformBufferOffsetAlignment;
                    break;
                }
            if (physical_device_) break;
        }
        if (!physical_device_)
            throw std::runtime_error(config_.window
                                         ? "no Vulkan 1.3 device with a graphics queue that presents to the window"
                                         : "no Vulkan 1.3 device with a graphics queue");
        memory_properties_ = physical_device_->getMemoryProperties();
        float priority = 1.0f;
        vk::DeviceQueueCreateInfo queue_info({}, queue_family_, 1, &priority);
        std::vector<const char*> extensions;
        if (config_.window) extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
        // The features and extensions vkrc::Device enables (setup parity).
        for (const vk::ExtensionProperties& e : physical_device_->enumerateDeviceExtensionProperties())
            if (std::string_view(e.extensionName.data()) == VK_EXT_MEMORY_BUDGET_EXTENSION_NAME)
                extensions.push_back(VK_EXT_MEMORY_BUDGET_EXTENSION_NAME);
        vk::StructureChain<vk::DeviceCreateInfo, vk::PhysicalDeviceVulkan12Features, vk::PhysicalDeviceVulkan13Features>
            chain(vk::DeviceCreateInfo({}, queue_info, {}, extensions),
                  vk::PhysicalDeviceVulkan12Features().setTimelineSemaphore(true),
                  vk::PhysicalDeviceVulkan13Features()
                      .setSynchronization2(true)
                      .setDynamicRendering(true)
                      .setMaintenance4(true));
        device_.emplace(*physical_device_, chain.get<vk::DeviceCreateInfo>());
        queue_.emplace(*device_, queue_family_, 0);
    }

    std::uint32_t memory_type(std::uint32_t bits, vk::MemoryPropertyFlags wanted) const {
        for (std::uint32_t i = 0; i < memory_properties_.memoryTypeCount; ++i)
            if ((bits & (1u << i)) && (memory_properties_.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
        return UINT32_MAX;
    }

    // Same memory choice as the raw variants: host-written, device-local too
    // where offered.
    Buffer create_buffer(vk::DeviceSize size, vk::BufferUsageFlags usage) {
        Buffer b;
        b.buffer = vk::raii::Buffer(*device_, vk::BufferCreateInfo({}, size, usage));
        vk::MemoryRequirements requirements = b.buffer.getMemoryRequirements();
        const vk::MemoryPropertyFlags host =
            vk::MemoryPropertyFlagBits::eHostVisible | vk::MemoryPropertyFlagBits::eHostCoherent;
        std::uint32_t type = memory_type(requirements.memoryTypeBits, host | vk::MemoryPropertyFlagBits::eDeviceLocal);
        if (type == UINT32_MAX) type = memory_type(requirements.memoryTypeBits, host);
        b.memory = vk::raii::DeviceMemory(*device_, vk::MemoryAllocateInfo(requirements.size, type));
        b.buffer.bindMemory(*b.memory, 0);
        b.mapped = b.memory.mapMemory(0, VK_WHOLE_SIZE);
        return b;
    }

    // A device-local buffer filled through a host-visible staging buffer
    // (what vkrc::upload_buffer does), with a one-off command pool and fence.
    template <typename T>
    Buffer create_filled_buffer(const std::vector<T>& data, vk::BufferUsageFlags usage) {
        const vk::DeviceSize size = data.size() * sizeof(T);
        Buffer b;
        b.buffer =
            vk::raii::Buffer(*device_, vk::BufferCreateInfo({}, size, usage | vk::BufferUsageFlagBits::eTransferDst));
        vk::MemoryRequirements requirements = b.buffer.getMemoryRequirements();
        std::uint32_t type = memory_type(requirements.memoryTypeBits, vk::MemoryPropertyFlagBits::eDeviceLocal);
        if (type == UINT32_MAX) type = memory_type(requirements.memoryTypeBits, {});
        b.memory = vk::raii::DeviceMemory(*device_, vk::MemoryAllocateInfo(requirements.size, type));
        b.buffer.bindMemory(*b.memory, 0);

        Buffer staging = create_buffer(size, vk::BufferUsageFlagBits::eTransferSrc);
        std::memcpy(staging.mapped, data.data(), size);
        vk::raii::CommandPool pool(*device_,
                                   vk::CommandPoolCreateInfo(vk::CommandPoolCreateFlagBits::eTransient, queue_family_));
        vk::raii::CommandBuffer cmd = std::move(vk::raii::CommandBuffers(
            *device_, vk::CommandBufferAllocateInfo(*pool, vk::CommandBufferLevel::ePrimary, 1))[0]);
        vk::raii::Fence fence(*device_, vk::FenceCreateInfo());
        cmd.begin({vk::CommandBufferUsageFlagBits::eOneTimeSubmit});
        cmd.copyBuffer(*staging.buffer, *b.buffer, vk::BufferCopy(0, 0, size));
        vk::BufferMemoryBarrier2 to_read(vk::PipelineStageFlagBits2::eCopy, vk::AccessFlagBits2::eTransferWrite,
                                         vk::PipelineStageFlagBits2::eAllCommands, vk::AccessFlagBits2::eMemoryRead,
                                         VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED, *b.buffer, 0, VK_WHOLE_SIZE);
        cmd.pipelineBarrier2(vk::DependencyInfo({}, {}, to_read, {}));
        cmd.end();
        vk::CommandBufferSubmitInfo cmd_info(*cmd);
        queue_->submit2(vk::SubmitInfo2({}, {}, cmd_info, {}), *fence);
        (void)device_->waitForFences(*fence, VK_TRUE, UINT64_MAX);
        return b;
    }

    void create_geometry(const Mesh& mesh) {
        positions_ = create_filled_buffer(mesh.positions, vk::BufferUsageFlagBits::eVertexBuffer);
        normals_ = create_filled_buffer(mesh.normals, vk::BufferUsageFlagBits::eVertexBuffer);
        indices_ = create_filled_buffer(mesh.indices, vk::BufferUsageFlagBits::eIndexBuffer);
        uniform_stride_ = (sizeof(CameraUniforms) + uniform_alignment_ - 1) / uniform_alignment_ * uniform_alignment_;
        uniform_ = create_buffer(uniform_stride_ * config_.frames_in_flight, vk::BufferUsageFlagBits::eUniformBuffer);
        uniform_mapped_ = uniform_.mapped;
        readback_ =
            create_buffer(vk::DeviceSize(config_.width) * config_.height * 4, vk::BufferUsageFlagBits::eTransferDst);
    }

    Image create_image(vk::Format format, vk::ImageUsageFlags usage, vk::ImageAspectFlags aspect, vk::Extent2D extent) {
        Image image;
        image.image = vk::raii::Image(
            *device_, vk::ImageCreateInfo({}, vk::ImageType::e2D, format, {extent.width, extent.height, 1}, 1, 1,
                                          vk::SampleCountFlagBits::e1, vk::ImageTiling::eOptimal, usage));
        vk::MemoryRequirements requirements = image.image.getMemoryRequirements();
        std::uint32_t type = memory_type(requirements.memoryTypeBits, vk::MemoryPropertyFlagBits::eDeviceLocal);
        if (type == UINT32_MAX) type = memory_type(requirements.memoryTypeBits, {});
        image.memory = vk::raii::DeviceMemory(*device_, vk::MemoryAllocateInfo(requirements.size, type));
        image.image.bindMemory(*image.memory, 0);
        image.view = vk::raii::ImageView(*device_, vk::ImageViewCreateInfo({}, *image.image, vk::ImageViewType::e2D,
                                                                           format, {}, {aspect, 0, 1, 0, 1}));
        return image;
    }

    // The ring (windowed: the one offscreen image of the reference frame)
    // and a depth image covering every target.
    void create_images() {
        const int ring_size = config_.window ? 1 : config_.frames_in_flight + 1;
        for (int i = 0; i < ring_size; ++i)
            ring_.push_back(create_image(
                colour_format_, vk::ImageUsageFlagBits::eColorAttachment | vk::ImageUsageFlagBits::eTransferSrc,
                vk::ImageAspectFlagBits::eColor, {config_.width, config_.height}));
        create_depth();
    }

    void create_depth() {
        depth_extent_ = vk::Extent2D(std::max(config_.width, swapchain_extent_.width),
                                     std::max(config_.height, swapchain_extent_.height));
        depth_ = create_image(vk::Format(depth_format), vk::ImageUsageFlagBits::eDepthStencilAttachment,
                              vk::ImageAspectFlagBits::eDepth, depth_extent_);
    }

    // The window's swapchain by the convention's rule. Format and present
    // mode are chosen once: the pipeline is made for the format.
    void create_swapchain() {
        std::vector<VkSurfaceFormatKHR> formats;
        for (const vk::SurfaceFormatKHR& f : physical_device_->getSurfaceFormatsKHR(**surface_)) formats.push_back(f);
        surface_format_ = vk::SurfaceFormatKHR(choose_window_format(formats));
        colour_format_ = surface_format_.format;
        std::vector<VkPresentModeKHR> modes;
        for (vk::PresentModeKHR m : physical_device_->getSurfacePresentModesKHR(**surface_))
            modes.push_back(VkPresentModeKHR(m));
        present_mode_ = vk::PresentModeKHR(choose_present_mode(modes));
        while (!build_swapchain()) wait_window_events();
    }

    // A swapchain for the surface's current extent, retiring the previous
    // one (the device is idle); false while the surface has no area.
    bool build_swapchain() {
        const VkSurfaceCapabilitiesKHR caps = physical_device_->getSurfaceCapabilitiesKHR(**surface_);
        const VkExtent2D extent = swapchain_extent(config_, caps);
        if (extent.width == 0 || extent.height == 0) return false;
        vk::SwapchainCreateInfoKHR info(
            {}, **surface_, swapchain_image_request(config_, caps), surface_format_.format, surface_format_.colorSpace,
            vk::Extent2D(extent), 1, vk::ImageUsageFlagBits::eColorAttachment | vk::ImageUsageFlagBits::eTransferSrc,
            vk::SharingMode::eExclusive, {}, vk::SurfaceTransformFlagBitsKHR(caps.currentTransform),
            vk::CompositeAlphaFlagBitsKHR(composite_alpha(caps)), present_mode_, true, *swapchain_);
        swapchain_views_.clear();
        render_done_.clear();
        swapchain_ = vk::raii::SwapchainKHR(*device_, info);  // destroys the retired one
        swapchain_images_ = swapchain_.getImages();
        for (vk::Image image : swapchain_images_) {
            swapchain_views_.emplace_back(*device_,
                                          vk::ImageViewCreateInfo({}, image, vk::ImageViewType::e2D, colour_format_, {},
                                                                  {vk::ImageAspectFlagBits::eColor, 0, 1, 0, 1}));
            render_done_.emplace_back(*device_, vk::SemaphoreCreateInfo());
        }
        swapchain_extent_ = extent;
        return true;
    }

    void recreate_swapchain() {
        device_->waitIdle();
        while (!build_swapchain()) wait_window_events();
        if (swapchain_extent_.width > depth_extent_.width || swapchain_extent_.height > depth_extent_.height)
            create_depth();
        swapchain_stale_ = false;
    }

    void create_pipeline() {
        vk::DescriptorSetLayoutBinding binding(0, vk::DescriptorType::eUniformBuffer, 1,
                                               vk::ShaderStageFlagBits::eVertex);
        set_layout_ = vk::raii::DescriptorSetLayout(*device_, vk::DescriptorSetLayoutCreateInfo({}, binding));
        vk::PushConstantRange push(vk::ShaderStageFlagBits::eVertex, 0, sizeof(PushConstants));
        pipeline_layout_ = vk::raii::PipelineLayout(*device_, vk::PipelineLayoutCreateInfo({}, *set_layout_, push));
        vk::raii::ShaderModule vert(*device_, vk::ShaderModuleCreateInfo({}, vkrc_shaders::teapot_vert.size_bytes(),
                                                                         vkrc_shaders::teapot_vert.data()));
        vk::raii::ShaderModule frag(*device_, vk::ShaderModuleCreateInfo({}, vkrc_shaders::teapot_frag.size_bytes(),
                                                                         vkrc_shaders::teapot_frag.data()));
        std::array<vk::PipelineShaderStageCreateInfo, 2> stages{
            vk::PipelineShaderStageCreateInfo({}, vk::ShaderStageFlagBits::eVertex, *vert, "main"),
            vk::PipelineShaderStageCreateInfo({}, vk::ShaderStageFlagBits::eFragment, *frag, "main")};
        std::array<vk::VertexInputBindingDescription, 2> bindings{
            vk::VertexInputBindingDescription(0, sizeof(glm::vec3), vk::VertexInputRate::eVertex),
            vk::VertexInputBindingDescription(1, sizeof(glm::vec3), vk::VertexInputRate::eVertex)};
        std::array<vk::VertexInputAttributeDescription, 2> attributes{
            vk::VertexInputAttributeDescription(0, 0, vk::Format::eR32G32B32Sfloat, 0),
            vk::VertexInputAttributeDescription(1, 1, vk::Format::eR32G32B32Sfloat, 0)};
        vk::PipelineVertexInputStateCreateInfo vertex_input({}, bindings, attributes);
        vk::PipelineInputAssemblyStateCreateInfo assembly({}, vk::PrimitiveTopology::eTriangleList);
        vk::PipelineViewportStateCreateInfo viewport({}, 1, nullptr, 1, nullptr);
        vk::PipelineRasterizationStateCreateInfo raster({}, false, false, vk::PolygonMode::eFill,
                                                        vk::CullModeFlagBits::eNone, vk::FrontFace::eCounterClockwise,
                                                        false, 0, 0, 0, 1.0f);
        vk::PipelineMultisampleStateCreateInfo multisample({}, vk::SampleCountFlagBits::e1);
        vk::PipelineDepthStencilStateCreateInfo depth({}, true, true, vk::CompareOp::eLess);
        vk::PipelineColorBlendAttachmentState blend_attachment;
        blend_attachment.colorWriteMask = vk::ColorComponentFlagBits::eR | vk::ColorComponentFlagBits::eG |
                                          vk::ColorComponentFlagBits::eB | vk::ColorComponentFlagBits::eA;
        vk::PipelineColorBlendStateCreateInfo blend({}, false, vk::LogicOp::eClear, blend_attachment);
        std::array<vk::DynamicState, 2> dynamic_states{vk::DynamicState::eViewport, vk::DynamicState::eScissor};
        vk::PipelineDynamicStateCreateInfo dynamic({}, dynamic_states);
        vk::StructureChain<vk::GraphicsPipelineCreateInfo, vk::PipelineRenderingCreateInfo> chain(
            vk::GraphicsPipelineCreateInfo({}, stages, &vertex_input, &assembly, nullptr, &viewport, &raster,
                                           &multisample, &depth, &blend, &dynamic, *pipeline_layout_),
            vk::PipelineRenderingCreateInfo(0, colour_format_, vk::Format(depth_format)));
        pipeline_ = vk::raii::Pipeline(*device_, nullptr, chain.get<vk::GraphicsPipelineCreateInfo>());
    }

    void create_frames() {
        auto slots = static_cast<std::uint32_t>(config_.frames_in_flight);
        vk::DescriptorPoolSize pool_size(vk::DescriptorType::eUniformBuffer, slots);
        // vk::raii::DescriptorSet frees its set on destruction, which needs the flag.
        descriptor_pool_ = vk::raii::DescriptorPool(
            *device_,
            vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet, slots, pool_size));
        for (std::uint32_t i = 0; i < slots; ++i) {
            Frame f;
            f.pool = vk::raii::CommandPool(
                *device_, vk::CommandPoolCreateInfo(vk::CommandPoolCreateFlagBits::eTransient, queue_family_));
            f.cmd = std::move(vk::raii::CommandBuffers(
                *device_, vk::CommandBufferAllocateInfo(*f.pool, vk::CommandBufferLevel::ePrimary, 1))[0]);
            for (int t = 0; recorders_ && t < recorders_->size(); ++t) {
                f.thread_pools.emplace_back(
                    *device_, vk::CommandPoolCreateInfo(vk::CommandPoolCreateFlagBits::eTransient, queue_family_));
                f.secondaries.push_back(std::move(vk::raii::CommandBuffers(
                    *device_,
                    vk::CommandBufferAllocateInfo(*f.thread_pools.back(), vk::CommandBufferLevel::eSecondary, 1))[0]));
                f.secondary_handles.push_back(*f.secondaries.back());
            }
            f.fence = vk::raii::Fence(*device_, vk::FenceCreateInfo());
            if (config_.window) f.acquire_semaphore = vk::raii::Semaphore(*device_, vk::SemaphoreCreateInfo());
            f.descriptor_set = std::move(
                vk::raii::DescriptorSets(*device_, vk::DescriptorSetAllocateInfo(*descriptor_pool_, *set_layout_))[0]);
            vk::DescriptorBufferInfo buffer(*uniform_.buffer, i * uniform_stride_, sizeof(CameraUniforms));
            device_->updateDescriptorSets(
                vk::WriteDescriptorSet(*f.descriptor_set, 0, 0, vk::DescriptorType::eUniformBuffer, {}, buffer), {});
            frames_.push_back(std::move(f));
        }
    }

    Config config_;
    CameraUniforms camera_{};
    std::vector<PushConstants> draws_;
    ThreadPool* recorders_ = nullptr;  // --threads N > 1
    std::uint32_t index_count_ = 0;
    std::string device_name_;
    vk::DeviceSize uniform_alignment_ = 1;
    std::uint32_t queue_family_ = 0;
    vk::PhysicalDeviceMemoryProperties memory_properties_;

    // Declaration order is destruction order reversed: parents first.
    BenchWindow window_;  // windowed only; outlives the surface
    vk::raii::Context context_;
    std::optional<vk::raii::Instance> instance_;
    std::optional<vk::raii::DebugUtilsMessengerEXT> messenger_;
    std::optional<vk::raii::SurfaceKHR> surface_;
    std::optional<vk::raii::PhysicalDevice> physical_device_;
    std::optional<vk::raii::Device> device_;
    std::optional<vk::raii::Queue> queue_;
    Buffer positions_, normals_, indices_, uniform_, readback_;
    void* uniform_mapped_ = nullptr;
    vk::DeviceSize uniform_stride_ = 0;
    std::vector<Image> ring_;
    Image depth_;
    vk::Extent2D depth_extent_;
    vk::Format colour_format_ = vk::Format(colour_format);  // windowed: the swapchain's
    vk::SurfaceFormatKHR surface_format_;
    vk::PresentModeKHR present_mode_ = vk::PresentModeKHR::eFifo;
    vk::raii::SwapchainKHR swapchain_ = nullptr;
    VkExtent2D swapchain_extent_{};
    std::vector<vk::Image> swapchain_images_;
    std::vector<vk::raii::ImageView> swapchain_views_;
    std::vector<vk::raii::Semaphore> render_done_;  // one per swapchain image
    bool swapchain_stale_ = false;                  // OUT_OF_DATE or SUBOPTIMAL seen: re-create at the next acquire
    bool present_to_window_ = false;                // windowed, except for the reference frame
    vk::raii::DescriptorSetLayout set_layout_ = nullptr;
    vk::raii::PipelineLayout pipeline_layout_ = nullptr;
    vk::raii::Pipeline pipeline_ = nullptr;
    vk::raii::DescriptorPool descriptor_pool_ = nullptr;
    std::vector<Frame> frames_;

    std::uint64_t frame_ = 0;
    std::uint32_t slot_ = 0;
    std::uint32_t image_ = 0;
    std::uint32_t presented_image_ = 0;
    Target target_;
};

}  // namespace

std::unique_ptr<Variant> make_vkhpp_variant() { return std::make_unique<VkhppVariant>(); }

}  // namespace teapot
