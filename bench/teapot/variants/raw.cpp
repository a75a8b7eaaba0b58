// The raw C API variants: `raw` calls the loader's exported functions, as a
// careful C programmer would; `raw-direct` makes the same device-level calls
// through pointers from vkGetDeviceProcAddr, skipping the loader's
// trampolines (the floor for any wrapper). One template, Direct selects the
// dispatch at compile time so `raw` keeps plain direct calls. Windowed
// (--window), both present with their own VkSurfaceKHR/VkSwapchainKHR code.
#include "harness/thread_pool.hpp"
#include "harness/variant.hpp"
#include "harness/window.hpp"

#define GLFW_INCLUDE_NONE  // Vulkan only, no OpenGL headers
#include <GLFW/glfw3.h>

#include "shaders/teapot.frag.h"
#include "shaders/teapot.vert.h"

#include <array>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

namespace teapot {
namespace {

void check(VkResult result, const char* call) {
    if (result != VK_SUCCESS)
        throw std::runtime_error(std::string(call) + " failed: VkResult " + std::to_string(result));
}

// clang-format off
// Device-level functions the variant calls.
#define TEAPOT_DEVICE_FUNCTIONS(X)                                                                               \
    X(vkDestroyDevice) X(vkGetDeviceQueue) X(vkDeviceWaitIdle) X(vkCreateBuffer) X(vkDestroyBuffer)               \
    X(vkGetBufferMemoryRequirements) X(vkAllocateMemory) X(vkFreeMemory) X(vkBindBufferMemory) X(vkMapMemory)     \
    X(vkCreateImage) X(vkDestroyImage) X(vkGetImageMemoryRequirements) X(vkBindImageMemory) X(vkCreateImageView)  \
    X(vkDestroyImageView) X(vkCreateShaderModule) X(vkDestroyShaderModule) X(vkCreateDescriptorSetLayout)         \
    X(vkDestroyDescriptorSetLayout) X(vkCreatePipelineLayout) X(vkDestroyPipelineLayout)                          \
    X(vkCreateGraphicsPipelines) X(vkDestroyPipeline) X(vkCreateDescriptorPool) X(vkDestroyDescriptorPool)        \
    X(vkAllocateDescriptorSets) X(vkUpdateDescriptorSets) X(vkCreateCommandPool) X(vkDestroyCommandPool)          \
    X(vkAllocateCommandBuffers) X(vkResetCommandPool) X(vkBeginCommandBuffer) X(vkEndCommandBuffer)               \
    X(vkCreateFence) X(vkDestroyFence) X(vkWaitForFences) X(vkResetFences) X(vkQueueSubmit2)                      \
    X(vkCmdPipelineBarrier2) X(vkCmdBeginRendering) X(vkCmdEndRendering) X(vkCmdBindPipeline)                     \
    X(vkCmdSetViewport) X(vkCmdSetScissor) X(vkCmdBindDescriptorSets) X(vkCmdBindVertexBuffers)                   \
    X(vkCmdBindIndexBuffer) X(vkCmdPushConstants) X(vkCmdDrawIndexed) X(vkCmdCopyImageToBuffer) X(vkCmdCopyBuffer) \
    X(vkCmdExecuteCommands)                                                                                      \
    X(vkCreateSemaphore) X(vkDestroySemaphore) X(vkCreateSwapchainKHR) X(vkDestroySwapchainKHR)                   \
    X(vkGetSwapchainImagesKHR) X(vkAcquireNextImageKHR) X(vkQueuePresentKHR)
// clang-format on

struct DeviceFunctions {
#define TEAPOT_MEMBER(name) PFN_##name name = nullptr;
    TEAPOT_DEVICE_FUNCTIONS(TEAPOT_MEMBER)
#undef TEAPOT_MEMBER
};

// A buffer or image with its own allocation.
struct Allocation {
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* mapped = nullptr;
};

// The helpers a careful C programmer writes once.

// An image barrier on the first mip level and layer of one aspect.
VkImageMemoryBarrier2 image_barrier(VkImage image, VkImageAspectFlags aspect, VkImageLayout old_layout,
                                    VkImageLayout new_layout, VkPipelineStageFlags2 src_stage,
                                    VkAccessFlags2 src_access, VkPipelineStageFlags2 dst_stage,
                                    VkAccessFlags2 dst_access) {
    VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    b.srcStageMask = src_stage;
    b.srcAccessMask = src_access;
    b.dstStageMask = dst_stage;
    b.dstAccessMask = dst_access;
    b.oldLayout = old_layout;
    b.newLayout = new_layout;
    b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {aspect, 0, 1, 0, 1};
    return b;
}

// Records the image barriers into cmd with vkCmdPipelineBarrier2.
void pipeline_barrier(PFN_vkCmdPipelineBarrier2 barrier, VkCommandBuffer cmd,
                      std::span<const VkImageMemoryBarrier2> images,
                      std::span<const VkBufferMemoryBarrier2> buffers = {}) {
    VkDependencyInfo dependency{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dependency.imageMemoryBarrierCount = static_cast<std::uint32_t>(images.size());
    dependency.pImageMemoryBarriers = images.data();
    dependency.bufferMemoryBarrierCount = static_cast<std::uint32_t>(buffers.size());
    dependency.pBufferMemoryBarriers = buffers.data();
    barrier(cmd, &dependency);
}

// Begins a one-time-submit recording of cmd after resetting its pool.
// Copies the first mip level of a colour image (already in TRANSFER_SRC
// layout) to a host-visible buffer and makes the bytes visible to the host;
// after_copy, when given, rides in the same barrier (a layout change back).
void copy_image_to_host(const DeviceFunctions& fn, VkCommandBuffer cmd, VkImage image, VkExtent2D extent,
                        VkBuffer buffer, std::span<const VkImageMemoryBarrier2> after_copy = {}) {
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {extent.width, extent.height, 1};
    fn.vkCmdCopyImageToBuffer(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer, 1, &region);
    VkBufferMemoryBarrier2 to_host{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2};
    to_host.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
    to_host.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    to_host.dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT;
    to_host.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT;
    to_host.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    to_host.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    to_host.buffer = buffer;
    to_host.size = VK_WHOLE_SIZE;
    pipeline_barrier(fn.vkCmdPipelineBarrier2, cmd, after_copy, {&to_host, 1});
}

void begin_one_time(const DeviceFunctions& fn, VkDevice device, VkCommandPool pool, VkCommandBuffer cmd) {
    check(fn.vkResetCommandPool(device, pool, 0), "vkResetCommandPool");
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(fn.vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
}

// Ends cmd, submits it signalling fence, waits for the fence and resets it.
void submit_and_wait(const DeviceFunctions& fn, VkDevice device, VkQueue queue, VkCommandBuffer cmd, VkFence fence) {
    check(fn.vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
    VkCommandBufferSubmitInfo cmd_info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
    cmd_info.commandBuffer = cmd;
    VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    submit.commandBufferInfoCount = 1;
    submit.pCommandBufferInfos = &cmd_info;
    check(fn.vkQueueSubmit2(queue, 1, &submit, fence), "vkQueueSubmit2");
    check(fn.vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    check(fn.vkResetFences(device, 1, &fence), "vkResetFences");
}

template <bool Direct>
class RawVariant final : public Variant {
    struct Frame;  // per frame slot, below
public:
    ~RawVariant() override { destroy(); }

    void init(const Config& config, const SceneData& scene) override {
        config_ = config;
        recorders_ = config.threads > 1 ? scene.recorders : nullptr;
        draws_.resize(config.teapots);
        mesh_.index_count = static_cast<std::uint32_t>(scene.mesh->indices.size());
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
            target_ = {ring_[image_].image,
                       ring_[image_].view,
                       {config_.width, config_.height},
                       VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
            return;
        }
        for (;;) {
            if (window_sc_.stale) recreate_swapchain();
            VkResult result = call(&DeviceFunctions::vkAcquireNextImageKHR, ::vkAcquireNextImageKHR)(
                device_, window_sc_.swapchain, UINT64_MAX, frames_[slot_].acquire_semaphore, VK_NULL_HANDLE, &image_);
            if (result == VK_ERROR_OUT_OF_DATE_KHR) {
                window_sc_.stale = true;
                continue;
            }
            if (result == VK_SUBOPTIMAL_KHR)
                window_sc_.stale = true;  // the image is still usable: re-created after its present
            else check(result, "vkAcquireNextImageKHR");
            break;
        }
        target_ = {window_sc_.images[image_], window_sc_.views[image_], window_sc_.extent,
                   VK_IMAGE_LAYOUT_PRESENT_SRC_KHR};
    }

    void uniform() override {
        write_camera_uniforms(static_cast<char*>(uniform_.mapped) + slot_ * uniform_stride_, camera_,
                              config_.uniform_writes);
    }

    void command() override {
        Frame& f = frames_[slot_];
        check(call(&DeviceFunctions::vkResetCommandPool, ::vkResetCommandPool)(device_, f.pool, 0),
              "vkResetCommandPool");
        VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        VkCommandBuffer cmd = f.cmd;
        check(call(&DeviceFunctions::vkBeginCommandBuffer, ::vkBeginCommandBuffer)(cmd, &begin),
              "vkBeginCommandBuffer");
        const bool threaded = !f.secondaries.empty();
        begin_target(cmd, threaded ? VK_RENDERING_CONTENTS_SECONDARY_COMMAND_BUFFERS_BIT : 0);
        if (threaded) record_on_threads(f);
        else record_draws(cmd, f, {0, draws_.size()});
        end_target(cmd);
    }

    // The barriers into the attachment layouts and the rendering's begin.
    void begin_target(VkCommandBuffer cmd, VkRenderingFlags flags) const {
        const VkPipelineStageFlags2 depth_stages =
            VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
        const VkImageMemoryBarrier2 to_render[2] = {
            image_barrier(target_.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                          VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, 0,
                          VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT),
            image_barrier(
                depth_.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, depth_stages, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                depth_stages,
                VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT)};
        pipeline_barrier(call(&DeviceFunctions::vkCmdPipelineBarrier2, ::vkCmdPipelineBarrier2), cmd, to_render);

        VkRenderingAttachmentInfo colour{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
        colour.imageView = target_.view;
        colour.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
        colour.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
        colour.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        std::memcpy(colour.clearValue.color.float32, clear_colour, sizeof clear_colour);
        VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
        depth.imageView = depth_.view;
        depth.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
        depth.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
        depth.storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
        depth.clearValue.depthStencil = {1.0f, 0};
        VkRenderingInfo rendering{VK_STRUCTURE_TYPE_RENDERING_INFO};
        rendering.flags = flags;
        rendering.renderArea = {{0, 0}, target_.extent};
        rendering.layerCount = 1;
        rendering.colorAttachmentCount = 1;
        rendering.pColorAttachments = &colour;
        rendering.pDepthAttachment = &depth;
        call(&DeviceFunctions::vkCmdBeginRendering, ::vkCmdBeginRendering)(cmd, &rendering);
    }

    // The state every draw needs, then the draws of range: into the primary,
    // or one thread's slice into its secondary (which inherits no state).
    void record_draws(VkCommandBuffer cmd, const Frame& f, DrawRange range) const {
        call(&DeviceFunctions::vkCmdBindPipeline, ::vkCmdBindPipeline)(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_);
        VkViewport viewport{0, 0, float(target_.extent.width), float(target_.extent.height), 0, 1};
        call(&DeviceFunctions::vkCmdSetViewport, ::vkCmdSetViewport)(cmd, 0, 1, &viewport);
        VkRect2D scissor{{0, 0}, target_.extent};
        call(&DeviceFunctions::vkCmdSetScissor, ::vkCmdSetScissor)(cmd, 0, 1, &scissor);
        call(&DeviceFunctions::vkCmdBindDescriptorSets, ::vkCmdBindDescriptorSets)(
            cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_layout_, 0, 1, &f.descriptor_set, 0, nullptr);
        VkBuffer vertex_buffers[2] = {mesh_.positions, mesh_.normals};
        VkDeviceSize offsets[2] = {0, 0};
        call(&DeviceFunctions::vkCmdBindVertexBuffers, ::vkCmdBindVertexBuffers)(cmd, 0, 2, vertex_buffers, offsets);
        call(&DeviceFunctions::vkCmdBindIndexBuffer, ::vkCmdBindIndexBuffer)(cmd, mesh_.indices, 0,
                                                                             VK_INDEX_TYPE_UINT16);
        auto push = call(&DeviceFunctions::vkCmdPushConstants, ::vkCmdPushConstants);
        auto draw = call(&DeviceFunctions::vkCmdDrawIndexed, ::vkCmdDrawIndexed);
        for (std::size_t i = range.first; i < range.last; ++i) {
            push(cmd, pipeline_layout_, VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof(PushConstants), &draws_[i]);
            draw(cmd, mesh_.index_count, 1, 0, 0, 0);
        }
    }

    // --threads N: thread i records its slice into the secondary of its own
    // pool; the primary executes them in thread order.
    void record_on_threads(const Frame& f) const {
        const int threads = int(f.secondaries.size());
        auto record = [&](int i) {
            const auto t = std::size_t(i);
            check(call(&DeviceFunctions::vkResetCommandPool, ::vkResetCommandPool)(device_, f.thread_pools[t], 0),
                  "vkResetCommandPool");
            VkCommandBufferInheritanceRenderingInfo rendering{
                VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_RENDERING_INFO};
            rendering.colorAttachmentCount = 1;
            rendering.pColorAttachmentFormats = &colour_format_;
            rendering.depthAttachmentFormat = depth_format;
            rendering.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
            VkCommandBufferInheritanceInfo inheritance{VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_INFO};
            inheritance.pNext = &rendering;
            VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
            begin.flags =
                VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT | VK_COMMAND_BUFFER_USAGE_RENDER_PASS_CONTINUE_BIT;
            begin.pInheritanceInfo = &inheritance;
            VkCommandBuffer secondary = f.secondaries[t];
            check(call(&DeviceFunctions::vkBeginCommandBuffer, ::vkBeginCommandBuffer)(secondary, &begin),
                  "vkBeginCommandBuffer");
            record_draws(secondary, f, draw_range(i, threads, draws_.size()));
            check(call(&DeviceFunctions::vkEndCommandBuffer, ::vkEndCommandBuffer)(secondary), "vkEndCommandBuffer");
        };
        recorders_->run(record);
        call(&DeviceFunctions::vkCmdExecuteCommands, ::vkCmdExecuteCommands)(
            f.cmd, static_cast<std::uint32_t>(f.secondaries.size()), f.secondaries.data());
    }

    // The rendering's end, the barrier to the presentation layout and the end.
    void end_target(VkCommandBuffer cmd) const {
        call(&DeviceFunctions::vkCmdEndRendering, ::vkCmdEndRendering)(cmd);
        const VkImageMemoryBarrier2 to_present =
            image_barrier(target_.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                          target_.present_layout, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                          VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_NONE, 0);
        pipeline_barrier(call(&DeviceFunctions::vkCmdPipelineBarrier2, ::vkCmdPipelineBarrier2), cmd, {&to_present, 1});
        check(call(&DeviceFunctions::vkEndCommandBuffer, ::vkEndCommandBuffer)(cmd), "vkEndCommandBuffer");
    }

    void submit() override {
        Frame& f = frames_[slot_];
        VkCommandBufferSubmitInfo cmd_info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
        cmd_info.commandBuffer = f.cmd;
        VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
        submit.commandBufferInfoCount = 1;
        submit.pCommandBufferInfos = &cmd_info;
        VkSemaphoreSubmitInfo wait{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
        VkSemaphoreSubmitInfo signal{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
        if (present_to_window_) {
            wait.semaphore = f.acquire_semaphore;
            wait.stageMask = VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;
            signal.semaphore = window_sc_.render_done[image_];
            signal.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
            submit.waitSemaphoreInfoCount = 1;
            submit.pWaitSemaphoreInfos = &wait;
            submit.signalSemaphoreInfoCount = 1;
            submit.pSignalSemaphoreInfos = &signal;
        }
        check(call(&DeviceFunctions::vkQueueSubmit2, ::vkQueueSubmit2)(queue_, 1, &submit, f.fence), "vkQueueSubmit2");
        f.submitted = true;
    }

    void present() override {
        if (present_to_window_) {
            VkPresentInfoKHR info{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
            info.waitSemaphoreCount = 1;
            info.pWaitSemaphores = &window_sc_.render_done[image_];
            info.swapchainCount = 1;
            info.pSwapchains = &window_sc_.swapchain;
            info.pImageIndices = &image_;
            VkResult result = call(&DeviceFunctions::vkQueuePresentKHR, ::vkQueuePresentKHR)(queue_, &info);
            if (result == VK_ERROR_OUT_OF_DATE_KHR || result == VK_SUBOPTIMAL_KHR)
                window_sc_.stale = true;  // re-created at the next acquire
            else check(result, "vkQueuePresentKHR");
        }
        presented_image_ = image_;
        ++frame_;
    }

    void wait() override {
        Frame& next = frames_[frame_ % config_.frames_in_flight];
        if (!next.submitted) return;
        check(call(&DeviceFunctions::vkWaitForFences, ::vkWaitForFences)(device_, 1, &next.fence, VK_TRUE, UINT64_MAX),
              "vkWaitForFences");
        check(call(&DeviceFunctions::vkResetFences, ::vkResetFences)(device_, 1, &next.fence), "vkResetFences");
        next.submitted = false;
    }

    void update(double t) override { update_scene(config_, t, draws_, camera_); }

    void drain() override { check(fn_.vkDeviceWaitIdle(device_), "vkDeviceWaitIdle"); }

    std::vector<std::uint8_t> render_reference_frame(double t) override {
        drain();
        update(t);
        // Offscreen in both modes, through the headless path of the stages.
        present_to_window_ = false;
        acquire();
        uniform();
        command();
        submit();
        present();
        wait();  // the other slot's last frame: every slot is free afterwards
        present_to_window_ = config_.window;
        return read_back_ring_image();
    }

    std::vector<std::uint8_t> read_back_last_frame(double t) override {
        if (config_.window) return read_back_presented_frame(t);
        return read_back_ring_image();
    }

    // Windowed: one more frame at time t through the window's stages, its
    // swapchain image copied to the readback buffer (the swapchain has
    // TRANSFER_SRC usage) between its rendering and its presentation: the
    // submission renders (waiting on the acquire semaphore), then a one-off
    // copy goes PRESENT_SRC -> TRANSFER_SRC -> PRESENT_SRC and signals the
    // render-done semaphore that present waits on.
    std::vector<std::uint8_t> read_back_presented_frame(double t) {
        drain();
        update(t);
        acquire();
        uniform();
        command();
        if (window_sc_.extent.width != config_.width || window_sc_.extent.height != config_.height)
            throw std::runtime_error("windowed image check: the swapchain's extent is not --size");
        Frame& f = frames_[slot_];
        VkCommandBufferSubmitInfo cmd_info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
        cmd_info.commandBuffer = f.cmd;
        VkSemaphoreSubmitInfo wait_info{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
        wait_info.semaphore = f.acquire_semaphore;
        wait_info.stageMask = VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;
        VkSubmitInfo2 render{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
        render.waitSemaphoreInfoCount = 1;
        render.pWaitSemaphoreInfos = &wait_info;
        render.commandBufferInfoCount = 1;
        render.pCommandBufferInfos = &cmd_info;
        check(fn_.vkQueueSubmit2(queue_, 1, &render, f.fence), "vkQueueSubmit2");
        check(fn_.vkWaitForFences(device_, 1, &f.fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
        check(fn_.vkResetFences(device_, 1, &f.fence), "vkResetFences");

        begin_one_time(fn_, device_, f.pool, f.cmd);
        const VkImage image = window_sc_.images[image_];
        const VkImageMemoryBarrier2 to_copy = image_barrier(
            image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
            VK_PIPELINE_STAGE_2_NONE, 0, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
        pipeline_barrier(fn_.vkCmdPipelineBarrier2, f.cmd, {&to_copy, 1});
        const VkImageMemoryBarrier2 back = image_barrier(
            image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
            VK_PIPELINE_STAGE_2_COPY_BIT, 0, VK_PIPELINE_STAGE_2_NONE, 0);
        copy_image_to_host(fn_, f.cmd, image, window_sc_.extent, readback_buffer_, {&back, 1});
        check(fn_.vkEndCommandBuffer(f.cmd), "vkEndCommandBuffer");
        cmd_info.commandBuffer = f.cmd;
        VkSemaphoreSubmitInfo signal{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
        signal.semaphore = window_sc_.render_done[image_];
        signal.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
        VkSubmitInfo2 copy{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
        copy.commandBufferInfoCount = 1;
        copy.pCommandBufferInfos = &cmd_info;
        copy.signalSemaphoreInfoCount = 1;
        copy.pSignalSemaphoreInfos = &signal;
        check(fn_.vkQueueSubmit2(queue_, 1, &copy, f.fence), "vkQueueSubmit2");
        check(fn_.vkWaitForFences(device_, 1, &f.fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
        check(fn_.vkResetFences(device_, 1, &f.fence), "vkResetFences");
        const auto* pixels = static_cast<const std::uint8_t*>(readback_.mapped);
        std::vector<std::uint8_t> bytes(pixels,
                                        pixels + std::size_t(window_sc_.extent.width) * window_sc_.extent.height * 4);
        to_rgba(bytes, colour_format_);
        present();
        wait();
        drain();
        return bytes;
    }

    std::string device_name() const override { return device_name_; }

    const BenchWindow* window() const override { return config_.window ? &window_ : nullptr; }

    std::string presentation() const override {
        return config_.window ? swapchain_presentation(colour_format_, window_sc_.present_mode,
                                                       window_sc_.images.size(), window_sc_.extent)
                              : headless_presentation(ring_.size(), colour_format_, {config_.width, config_.height});
    }

private:
    struct Image {
        VkImage image = VK_NULL_HANDLE;
        VkImageView view = VK_NULL_HANDLE;
        VkDeviceMemory memory = VK_NULL_HANDLE;
    };
    struct Frame {
        VkCommandPool pool = VK_NULL_HANDLE;
        VkCommandBuffer cmd = VK_NULL_HANDLE;
        VkFence fence = VK_NULL_HANDLE;
        VkDescriptorSet descriptor_set = VK_NULL_HANDLE;
        VkSemaphore acquire_semaphore = VK_NULL_HANDLE;  // windowed only
        bool submitted = false;
        // --threads N > 1: per thread, a pool and its secondary.
        std::vector<VkCommandPool> thread_pools;
        std::vector<VkCommandBuffer> secondaries;
    };
    // The mesh: three device-local buffers filled by a staging upload.
    struct MeshBuffers {
        VkBuffer positions = VK_NULL_HANDLE, normals = VK_NULL_HANDLE, indices = VK_NULL_HANDLE;
        Allocation positions_memory, normals_memory, indices_memory;
        std::uint32_t index_count = 0;
    };
    // Windowed: the surface, the swapchain by the convention's rule and its
    // per-image objects.
    struct WindowSwapchain {
        VkSurfaceKHR surface = VK_NULL_HANDLE;
        VkSurfaceFormatKHR surface_format{};
        VkPresentModeKHR present_mode = VK_PRESENT_MODE_FIFO_KHR;
        VkSwapchainKHR swapchain = VK_NULL_HANDLE;
        VkExtent2D extent{};
        std::vector<VkImage> images;
        std::vector<VkImageView> views;
        std::vector<VkSemaphore> render_done;  // one per swapchain image
        bool stale = false;                    // OUT_OF_DATE or SUBOPTIMAL seen: re-create at the next acquire
    };
    // What this frame renders into: a ring image or a swapchain image.
    struct Target {
        VkImage image = VK_NULL_HANDLE;
        VkImageView view = VK_NULL_HANDLE;
        VkExtent2D extent{};
        VkImageLayout present_layout = VK_IMAGE_LAYOUT_UNDEFINED;
    };

    // The device-level function: the loader's export for raw, the device's
    // own pointer for raw-direct. Resolved at compile time.
    template <typename Pfn>
    Pfn call(Pfn DeviceFunctions::*member, Pfn exported) const {
        if constexpr (Direct) return fn_.*member;
        else return exported;
    }

    // Drains, then copies the ring image last presented to the readback
    // buffer with a one-off command buffer from the last frame's slot.
    std::vector<std::uint8_t> read_back_ring_image() {
        drain();
        Frame& f = frames_[slot_];
        if (f.submitted) {
            check(fn_.vkWaitForFences(device_, 1, &f.fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
            check(fn_.vkResetFences(device_, 1, &f.fence), "vkResetFences");
            f.submitted = false;
        }
        begin_one_time(fn_, device_, f.pool, f.cmd);
        const VkImage image = ring_[presented_image_].image;
        const VkImageMemoryBarrier2 to_copy = image_barrier(
            image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
            VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
            VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
        pipeline_barrier(fn_.vkCmdPipelineBarrier2, f.cmd, {&to_copy, 1});
        copy_image_to_host(fn_, f.cmd, image, {config_.width, config_.height}, readback_buffer_);
        submit_and_wait(fn_, device_, queue_, f.cmd, f.fence);
        const auto* pixels = static_cast<const std::uint8_t*>(readback_.mapped);
        std::vector<std::uint8_t> image_bytes(pixels, pixels + std::size_t(config_.width) * config_.height * 4);
        to_rgba(image_bytes, colour_format_);
        return image_bytes;
    }

    void create_instance() {
        VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
        app.pApplicationName = "teapot";
        app.apiVersion = VK_API_VERSION_1_3;
        VkDebugUtilsMessengerCreateInfoEXT messenger{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
        messenger.messageSeverity = validation_severities;
        messenger.messageType = validation_types;
        messenger.pfnUserCallback = validation_callback;
        std::vector<const char*> extensions;
        if (config_.window) {
            window_ = BenchWindow(config_);
            extensions = window_instance_extensions();
        }
        if (config_.validation) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
        info.pApplicationInfo = &app;
        info.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
        info.ppEnabledExtensionNames = extensions.data();
        if (config_.validation) {
            info.pNext = &messenger;
            info.enabledLayerCount = 1;
            info.ppEnabledLayerNames = &validation_layer;
        }
        check(vkCreateInstance(&info, nullptr, &instance_), "vkCreateInstance");
        if (config_.window)
            check(glfwCreateWindowSurface(instance_, window_.get(), nullptr, &window_sc_.surface),
                  "glfwCreateWindowSurface");
        if (config_.validation) {
            auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
                vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
            check(create(instance_, &messenger, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
        }
    }

    void create_device() {
        // The first device with a graphics queue and Vulkan 1.3 (windowed:
        // a graphics queue that presents to the surface).
        std::uint32_t count = 0;
        check(vkEnumeratePhysicalDevices(instance_, &count, nullptr), "vkEnumeratePhysicalDevices");
        std::vector<VkPhysicalDevice> devices(count);
        check(vkEnumeratePhysicalDevices(instance_, &count, devices.data()), "vkEnumeratePhysicalDevices");
        for (VkPhysicalDevice candidate : devices) {
            VkPhysicalDeviceProperties properties;
            vkGetPhysicalDeviceProperties(candidate, &properties);
            if (properties.apiVersion < VK_API_VERSION_1_3) continue;
            std::uint32_t family_count = 0;
            vkGetPhysicalDeviceQueueFamilyProperties(candidate, &family_count, nullptr);
            std::vector<VkQueueFamilyProperties> families(family_count);
            vkGetPhysicalDeviceQueueFamilyProperties(candidate, &family_count, families.data());
            for (std::uint32_t i = 0; i < family_count; ++i) {
                VkBool32 presents = VK_TRUE;
                if (config_.window)
                    check(vkGetPhysicalDeviceSurfaceSupportKHR(candidate, i, window_sc_.surface, &presents),
                          "vkGetPhysicalDeviceSurfaceSupportKHR");
                if ((families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) && presents) {
                    physical_device_ = candidate;
                    queue_family_ = i;
                    device_name_ = properties.deviceName;
                    uniform_alignment_ = properties.limits.minUniformBufferOffsetAlignment;
                    break;
                }
            }
            if (physical_device_) break;
        }
        if (!physical_device_)
            throw std::runtime_error(config_.window
                                         ? "no Vulkan 1.3 device with a graphics queue that presents to the window"
                                         : "no Vulkan 1.3 device with a graphics queue");
        vkGetPhysicalDeviceMemoryProperties(physical_device_, &memory_properties_);

        float priority = 1.0f;
        VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
        queue_info.queueFamilyIndex = queue_family_;
        queue_info.queueCount = 1;
        queue_info.pQueuePriorities = &priority;
        // The features and extensions vkrc::Device enables (setup parity):
        // synchronization2, dynamicRendering, maintenance4, timelineSemaphore,
        // VK_EXT_memory_budget where supported.
        VkPhysicalDeviceVulkan13Features features13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
        features13.synchronization2 = VK_TRUE;
        features13.dynamicRendering = VK_TRUE;
        features13.maintenance4 = VK_TRUE;
        VkPhysicalDeviceVulkan12Features features12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
        features12.pNext = &features13;
        features12.timelineSemaphore = VK_TRUE;
        VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
        info.pNext = &features12;
        info.queueCreateInfoCount = 1;
        info.pQueueCreateInfos = &queue_info;
        std::vector<const char*> extensions;
        if (config_.window) extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
        if (supports_device_extension(VK_EXT_MEMORY_BUDGET_EXTENSION_NAME))
            extensions.push_back(VK_EXT_MEMORY_BUDGET_EXTENSION_NAME);
        info.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
        info.ppEnabledExtensionNames = extensions.data();
        check(vkCreateDevice(physical_device_, &info, nullptr, &device_), "vkCreateDevice");
        // The pointers for raw-direct's hot path and for the untimed helpers.
#define TEAPOT_LOAD(name) fn_.name = reinterpret_cast<PFN_##name>(vkGetDeviceProcAddr(device_, #name));
        TEAPOT_DEVICE_FUNCTIONS(TEAPOT_LOAD)
#undef TEAPOT_LOAD
        fn_.vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
    }

    bool supports_device_extension(const char* name) const {
        std::uint32_t count = 0;
        check(vkEnumerateDeviceExtensionProperties(physical_device_, nullptr, &count, nullptr),
              "vkEnumerateDeviceExtensionProperties");
        std::vector<VkExtensionProperties> extensions(count);
        check(vkEnumerateDeviceExtensionProperties(physical_device_, nullptr, &count, extensions.data()),
              "vkEnumerateDeviceExtensionProperties");
        for (const VkExtensionProperties& e : extensions)
            if (std::strcmp(e.extensionName, name) == 0) return true;
        return false;
    }

    std::uint32_t memory_type(std::uint32_t bits, VkMemoryPropertyFlags wanted) const {
        for (std::uint32_t i = 0; i < memory_properties_.memoryTypeCount; ++i)
            if ((bits & (1u << i)) && (memory_properties_.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
        return UINT32_MAX;
    }

    // A buffer in memory the host writes directly: device-local as well where
    // the device offers that (integrated GPUs, lavapipe, resizable BAR).
    VkBuffer create_buffer(VkDeviceSize size, VkBufferUsageFlags usage, Allocation& allocation) {
        VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
        info.size = size;
        info.usage = usage;
        VkBuffer buffer;
        check(fn_.vkCreateBuffer(device_, &info, nullptr, &buffer), "vkCreateBuffer");
        VkMemoryRequirements requirements;
        fn_.vkGetBufferMemoryRequirements(device_, buffer, &requirements);
        const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
        std::uint32_t type = memory_type(requirements.memoryTypeBits, host | VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        if (type == UINT32_MAX) type = memory_type(requirements.memoryTypeBits, host);
        VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
        allocate.allocationSize = requirements.size;
        allocate.memoryTypeIndex = type;
        check(fn_.vkAllocateMemory(device_, &allocate, nullptr, &allocation.memory), "vkAllocateMemory");
        check(fn_.vkBindBufferMemory(device_, buffer, allocation.memory, 0), "vkBindBufferMemory");
        check(fn_.vkMapMemory(device_, allocation.memory, 0, VK_WHOLE_SIZE, 0, &allocation.mapped), "vkMapMemory");
        return buffer;
    }

    // A device-local buffer filled through a host-visible staging buffer
    // (what vkrc::upload_buffer does), with a one-off command pool and fence.
    template <typename T>
    VkBuffer create_filled_buffer(const std::vector<T>& data, VkBufferUsageFlags usage, Allocation& allocation) {
        const VkDeviceSize size = data.size() * sizeof(T);
        VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
        info.size = size;
        info.usage = usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
        VkBuffer buffer;
        check(fn_.vkCreateBuffer(device_, &info, nullptr, &buffer), "vkCreateBuffer");
        VkMemoryRequirements requirements;
        fn_.vkGetBufferMemoryRequirements(device_, buffer, &requirements);
        std::uint32_t type = memory_type(requirements.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        if (type == UINT32_MAX) type = memory_type(requirements.memoryTypeBits, 0);
        VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
        allocate.allocationSize = requirements.size;
        allocate.memoryTypeIndex = type;
        check(fn_.vkAllocateMemory(device_, &allocate, nullptr, &allocation.memory), "vkAllocateMemory");
        check(fn_.vkBindBufferMemory(device_, buffer, allocation.memory, 0), "vkBindBufferMemory");

        Allocation staging_memory;
        VkBuffer staging = create_buffer(size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, staging_memory);
        std::memcpy(staging_memory.mapped, data.data(), size);
        VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
        pool_info.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
        pool_info.queueFamilyIndex = queue_family_;
        VkCommandPool pool;
        check(fn_.vkCreateCommandPool(device_, &pool_info, nullptr, &pool), "vkCreateCommandPool");
        VkCommandBufferAllocateInfo cmd_info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
        cmd_info.commandPool = pool;
        cmd_info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
        cmd_info.commandBufferCount = 1;
        VkCommandBuffer cmd;
        check(fn_.vkAllocateCommandBuffers(device_, &cmd_info, &cmd), "vkAllocateCommandBuffers");
        VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
        VkFence fence;
        check(fn_.vkCreateFence(device_, &fence_info, nullptr, &fence), "vkCreateFence");
        begin_one_time(fn_, device_, pool, cmd);
        VkBufferCopy region{0, 0, size};
        fn_.vkCmdCopyBuffer(cmd, staging, buffer, 1, &region);
        // Visible to every later command (vertex input and index reads).
        VkBufferMemoryBarrier2 to_read{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2};
        to_read.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
        to_read.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
        to_read.dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
        to_read.dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT;
        to_read.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        to_read.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        to_read.buffer = buffer;
        to_read.size = VK_WHOLE_SIZE;
        pipeline_barrier(fn_.vkCmdPipelineBarrier2, cmd, {}, {&to_read, 1});
        submit_and_wait(fn_, device_, queue_, cmd, fence);
        fn_.vkDestroyFence(device_, fence, nullptr);
        fn_.vkDestroyCommandPool(device_, pool, nullptr);
        fn_.vkDestroyBuffer(device_, staging, nullptr);
        fn_.vkFreeMemory(device_, staging_memory.memory, nullptr);
        return buffer;
    }

    void create_geometry(const Mesh& mesh) {
        mesh_.positions =
            create_filled_buffer(mesh.positions, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, mesh_.positions_memory);
        mesh_.normals = create_filled_buffer(mesh.normals, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, mesh_.normals_memory);
        mesh_.indices = create_filled_buffer(mesh.indices, VK_BUFFER_USAGE_INDEX_BUFFER_BIT, mesh_.indices_memory);
        uniform_stride_ = (sizeof(CameraUniforms) + uniform_alignment_ - 1) / uniform_alignment_ * uniform_alignment_;
        uniform_buffer_ =
            create_buffer(uniform_stride_ * config_.frames_in_flight, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, uniform_);
        readback_buffer_ = create_buffer(VkDeviceSize(config_.width) * config_.height * 4,
                                         VK_BUFFER_USAGE_TRANSFER_DST_BIT, readback_);
    }

    VkImageView create_view(VkImage image, VkFormat format, VkImageAspectFlags aspect) {
        VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
        view.image = image;
        view.viewType = VK_IMAGE_VIEW_TYPE_2D;
        view.format = format;
        view.subresourceRange = {aspect, 0, 1, 0, 1};
        VkImageView handle;
        check(fn_.vkCreateImageView(device_, &view, nullptr, &handle), "vkCreateImageView");
        return handle;
    }

    Image create_image(VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect, VkExtent2D extent) {
        Image image;
        VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
        info.imageType = VK_IMAGE_TYPE_2D;
        info.format = format;
        info.extent = {extent.width, extent.height, 1};
        info.mipLevels = 1;
        info.arrayLayers = 1;
        info.samples = VK_SAMPLE_COUNT_1_BIT;
        info.tiling = VK_IMAGE_TILING_OPTIMAL;
        info.usage = usage;
        check(fn_.vkCreateImage(device_, &info, nullptr, &image.image), "vkCreateImage");
        VkMemoryRequirements requirements;
        fn_.vkGetImageMemoryRequirements(device_, image.image, &requirements);
        std::uint32_t type = memory_type(requirements.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        if (type == UINT32_MAX) type = memory_type(requirements.memoryTypeBits, 0);
        VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
        allocate.allocationSize = requirements.size;
        allocate.memoryTypeIndex = type;
        check(fn_.vkAllocateMemory(device_, &allocate, nullptr, &image.memory), "vkAllocateMemory");
        check(fn_.vkBindImageMemory(device_, image.image, image.memory, 0), "vkBindImageMemory");
        image.view = create_view(image.image, format, aspect);
        return image;
    }

    void destroy_image(Image& image) {
        fn_.vkDestroyImageView(device_, image.view, nullptr);
        fn_.vkDestroyImage(device_, image.image, nullptr);
        fn_.vkFreeMemory(device_, image.memory, nullptr);
        image = {};
    }

    // The ring (windowed: the one offscreen image of the reference frame)
    // and a depth image covering every target.
    void create_images() {
        ring_.resize(config_.window ? 1 : config_.frames_in_flight + 1);
        for (Image& image : ring_)
            image = create_image(colour_format_, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                                 VK_IMAGE_ASPECT_COLOR_BIT, {config_.width, config_.height});
        create_depth();
    }

    void create_depth() {
        depth_extent_ = {std::max(config_.width, window_sc_.extent.width),
                         std::max(config_.height, window_sc_.extent.height)};
        depth_ = create_image(depth_format, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, VK_IMAGE_ASPECT_DEPTH_BIT,
                              depth_extent_);
    }

    // The window's swapchain by the convention's rule. Format and present
    // mode are chosen once: the pipeline is made for the format.
    void create_swapchain() {
        std::uint32_t count = 0;
        check(vkGetPhysicalDeviceSurfaceFormatsKHR(physical_device_, window_sc_.surface, &count, nullptr),
              "vkGetPhysicalDeviceSurfaceFormatsKHR");
        std::vector<VkSurfaceFormatKHR> formats(count);
        check(vkGetPhysicalDeviceSurfaceFormatsKHR(physical_device_, window_sc_.surface, &count, formats.data()),
              "vkGetPhysicalDeviceSurfaceFormatsKHR");
        window_sc_.surface_format = choose_window_format(formats);
        colour_format_ = window_sc_.surface_format.format;
        check(vkGetPhysicalDeviceSurfacePresentModesKHR(physical_device_, window_sc_.surface, &count, nullptr),
              "vkGetPhysicalDeviceSurfacePresentModesKHR");
        std::vector<VkPresentModeKHR> modes(count);
        check(vkGetPhysicalDeviceSurfacePresentModesKHR(physical_device_, window_sc_.surface, &count, modes.data()),
              "vkGetPhysicalDeviceSurfacePresentModesKHR");
        window_sc_.present_mode = choose_present_mode(modes);
        while (!build_swapchain()) wait_window_events();
    }

    // A swapchain for the surface's current extent, retiring the previous
    // one (the device is idle); false while the surface has no area.
    bool build_swapchain() {
        VkSurfaceCapabilitiesKHR caps;
        check(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical_device_, window_sc_.surface, &caps),
              "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
        const VkExtent2D extent = swapchain_extent(config_, caps);
        if (extent.width == 0 || extent.height == 0) return false;
        VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
        info.surface = window_sc_.surface;
        info.minImageCount = swapchain_image_request(config_, caps);
        info.imageFormat = window_sc_.surface_format.format;
        info.imageColorSpace = window_sc_.surface_format.colorSpace;
        info.imageExtent = extent;
        info.imageArrayLayers = 1;
        info.imageUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;  // the image check
        info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
        info.preTransform = caps.currentTransform;
        info.compositeAlpha = composite_alpha(caps);
        info.presentMode = window_sc_.present_mode;
        info.clipped = VK_TRUE;
        info.oldSwapchain = window_sc_.swapchain;
        VkSwapchainKHR swapchain = VK_NULL_HANDLE;
        const VkResult result = fn_.vkCreateSwapchainKHR(device_, &info, nullptr, &swapchain);
        destroy_swapchain();  // retired even if the creation failed
        check(result, "vkCreateSwapchainKHR");
        window_sc_.swapchain = swapchain;
        std::uint32_t count = 0;
        check(fn_.vkGetSwapchainImagesKHR(device_, window_sc_.swapchain, &count, nullptr), "vkGetSwapchainImagesKHR");
        window_sc_.images.resize(count);
        check(fn_.vkGetSwapchainImagesKHR(device_, window_sc_.swapchain, &count, window_sc_.images.data()),
              "vkGetSwapchainImagesKHR");
        VkSemaphoreCreateInfo semaphore{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
        for (VkImage image : window_sc_.images) {
            window_sc_.views.push_back(create_view(image, colour_format_, VK_IMAGE_ASPECT_COLOR_BIT));
            window_sc_.render_done.push_back(VK_NULL_HANDLE);
            check(fn_.vkCreateSemaphore(device_, &semaphore, nullptr, &window_sc_.render_done.back()),
                  "vkCreateSemaphore");
        }
        window_sc_.extent = extent;
        return true;
    }

    void recreate_swapchain() {
        check(fn_.vkDeviceWaitIdle(device_), "vkDeviceWaitIdle");
        while (!build_swapchain()) wait_window_events();
        if (window_sc_.extent.width > depth_extent_.width || window_sc_.extent.height > depth_extent_.height) {
            destroy_image(depth_);
            create_depth();
        }
        window_sc_.stale = false;
    }

    void destroy_swapchain() {
        for (VkImageView view : window_sc_.views) fn_.vkDestroyImageView(device_, view, nullptr);
        for (VkSemaphore semaphore : window_sc_.render_done) fn_.vkDestroySemaphore(device_, semaphore, nullptr);
        window_sc_.views.clear();
        window_sc_.render_done.clear();
        window_sc_.images.clear();
        if (window_sc_.swapchain) fn_.vkDestroySwapchainKHR(device_, window_sc_.swapchain, nullptr);
        window_sc_.swapchain = VK_NULL_HANDLE;
    }

    VkShaderModule create_shader(std::span<const std::uint32_t> code) {
        VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
        info.codeSize = code.size_bytes();
        info.pCode = code.data();
        VkShaderModule module;
        check(fn_.vkCreateShaderModule(device_, &info, nullptr, &module), "vkCreateShaderModule");
        return module;
    }

    void create_pipeline() {
        VkDescriptorSetLayoutBinding binding{0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT,
                                             nullptr};
        VkDescriptorSetLayoutCreateInfo set_layout{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
        set_layout.bindingCount = 1;
        set_layout.pBindings = &binding;
        check(fn_.vkCreateDescriptorSetLayout(device_, &set_layout, nullptr, &set_layout_),
              "vkCreateDescriptorSetLayout");
        VkPushConstantRange push{VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof(PushConstants)};
        VkPipelineLayoutCreateInfo layout{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
        layout.setLayoutCount = 1;
        layout.pSetLayouts = &set_layout_;
        layout.pushConstantRangeCount = 1;
        layout.pPushConstantRanges = &push;
        check(fn_.vkCreatePipelineLayout(device_, &layout, nullptr, &pipeline_layout_), "vkCreatePipelineLayout");

        VkShaderModule vert = create_shader(vkrc_shaders::teapot_vert);
        VkShaderModule frag = create_shader(vkrc_shaders::teapot_frag);
        VkPipelineShaderStageCreateInfo stages[2]{};
        stages[0] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
                     nullptr,
                     0,
                     VK_SHADER_STAGE_VERTEX_BIT,
                     vert,
                     "main",
                     nullptr};
        stages[1] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
                     nullptr,
                     0,
                     VK_SHADER_STAGE_FRAGMENT_BIT,
                     frag,
                     "main",
                     nullptr};
        VkVertexInputBindingDescription bindings[2] = {{0, sizeof(glm::vec3), VK_VERTEX_INPUT_RATE_VERTEX},
                                                       {1, sizeof(glm::vec3), VK_VERTEX_INPUT_RATE_VERTEX}};
        VkVertexInputAttributeDescription attributes[2] = {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0},
                                                           {1, 1, VK_FORMAT_R32G32B32_SFLOAT, 0}};
        VkPipelineVertexInputStateCreateInfo vertex_input{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
        vertex_input.vertexBindingDescriptionCount = 2;
        vertex_input.pVertexBindingDescriptions = bindings;
        vertex_input.vertexAttributeDescriptionCount = 2;
        vertex_input.pVertexAttributeDescriptions = attributes;
        VkPipelineInputAssemblyStateCreateInfo assembly{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
        assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
        VkPipelineViewportStateCreateInfo viewport{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
        viewport.viewportCount = 1;
        viewport.scissorCount = 1;
        VkPipelineRasterizationStateCreateInfo raster{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
        raster.polygonMode = VK_POLYGON_MODE_FILL;
        raster.cullMode = VK_CULL_MODE_NONE;  // the spout and lid openings show inner faces
        raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
        raster.lineWidth = 1.0f;
        VkPipelineMultisampleStateCreateInfo multisample{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
        multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
        VkPipelineDepthStencilStateCreateInfo depth{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
        depth.depthTestEnable = VK_TRUE;
        depth.depthWriteEnable = VK_TRUE;
        depth.depthCompareOp = VK_COMPARE_OP_LESS;
        VkPipelineColorBlendAttachmentState blend_attachment{};
        blend_attachment.colorWriteMask =
            VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
        VkPipelineColorBlendStateCreateInfo blend{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
        blend.attachmentCount = 1;
        blend.pAttachments = &blend_attachment;
        VkDynamicState dynamic_states[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
        VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
        dynamic.dynamicStateCount = 2;
        dynamic.pDynamicStates = dynamic_states;
        VkPipelineRenderingCreateInfo rendering{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
        rendering.colorAttachmentCount = 1;
        rendering.pColorAttachmentFormats = &colour_format_;
        rendering.depthAttachmentFormat = depth_format;
        VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
        info.pNext = &rendering;
        info.stageCount = 2;
        info.pStages = stages;
        info.pVertexInputState = &vertex_input;
        info.pInputAssemblyState = &assembly;
        info.pViewportState = &viewport;
        info.pRasterizationState = &raster;
        info.pMultisampleState = &multisample;
        info.pDepthStencilState = &depth;
        info.pColorBlendState = &blend;
        info.pDynamicState = &dynamic;
        info.layout = pipeline_layout_;
        VkResult result = fn_.vkCreateGraphicsPipelines(device_, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_);
        fn_.vkDestroyShaderModule(device_, vert, nullptr);
        fn_.vkDestroyShaderModule(device_, frag, nullptr);
        check(result, "vkCreateGraphicsPipelines");
    }

    VkCommandBuffer create_command_buffer(VkCommandPool pool, VkCommandBufferLevel level) {
        VkCommandBufferAllocateInfo allocate{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
        allocate.commandPool = pool;
        allocate.level = level;
        allocate.commandBufferCount = 1;
        VkCommandBuffer cmd = VK_NULL_HANDLE;
        check(fn_.vkAllocateCommandBuffers(device_, &allocate, &cmd), "vkAllocateCommandBuffers");
        return cmd;
    }

    void create_frames() {
        auto slots = static_cast<std::uint32_t>(config_.frames_in_flight);
        VkDescriptorPoolSize pool_size{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, slots};
        VkDescriptorPoolCreateInfo pool{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
        pool.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;  // as every variant's pool
        pool.maxSets = slots;
        pool.poolSizeCount = 1;
        pool.pPoolSizes = &pool_size;
        check(fn_.vkCreateDescriptorPool(device_, &pool, nullptr, &descriptor_pool_), "vkCreateDescriptorPool");
        frames_.resize(slots);
        for (std::uint32_t i = 0; i < slots; ++i) {
            Frame& f = frames_[i];
            VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
            pool_info.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
            pool_info.queueFamilyIndex = queue_family_;
            check(fn_.vkCreateCommandPool(device_, &pool_info, nullptr, &f.pool), "vkCreateCommandPool");
            f.cmd = create_command_buffer(f.pool, VK_COMMAND_BUFFER_LEVEL_PRIMARY);
            for (int t = 0; recorders_ && t < recorders_->size(); ++t) {
                f.thread_pools.push_back(VK_NULL_HANDLE);
                check(fn_.vkCreateCommandPool(device_, &pool_info, nullptr, &f.thread_pools.back()),
                      "vkCreateCommandPool");
                f.secondaries.push_back(
                    create_command_buffer(f.thread_pools.back(), VK_COMMAND_BUFFER_LEVEL_SECONDARY));
            }
            VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
            check(fn_.vkCreateFence(device_, &fence, nullptr, &f.fence), "vkCreateFence");
            if (config_.window) {
                VkSemaphoreCreateInfo semaphore{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
                check(fn_.vkCreateSemaphore(device_, &semaphore, nullptr, &f.acquire_semaphore), "vkCreateSemaphore");
            }
            VkDescriptorSetAllocateInfo set{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
            set.descriptorPool = descriptor_pool_;
            set.descriptorSetCount = 1;
            set.pSetLayouts = &set_layout_;
            check(fn_.vkAllocateDescriptorSets(device_, &set, &f.descriptor_set), "vkAllocateDescriptorSets");
            VkDescriptorBufferInfo buffer{uniform_buffer_, i * uniform_stride_, sizeof(CameraUniforms)};
            VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
            write.dstSet = f.descriptor_set;
            write.descriptorCount = 1;
            write.descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
            write.pBufferInfo = &buffer;
            fn_.vkUpdateDescriptorSets(device_, 1, &write, 0, nullptr);
        }
    }

    void destroy() {
        if (device_) {
            fn_.vkDeviceWaitIdle(device_);
            destroy_swapchain();
            for (Frame& f : frames_) {
                fn_.vkDestroySemaphore(device_, f.acquire_semaphore, nullptr);
                fn_.vkDestroyFence(device_, f.fence, nullptr);
                fn_.vkDestroyCommandPool(device_, f.pool, nullptr);
                for (VkCommandPool pool : f.thread_pools) fn_.vkDestroyCommandPool(device_, pool, nullptr);
            }
            fn_.vkDestroyDescriptorPool(device_, descriptor_pool_, nullptr);
            fn_.vkDestroyPipeline(device_, pipeline_, nullptr);
            fn_.vkDestroyPipelineLayout(device_, pipeline_layout_, nullptr);
            fn_.vkDestroyDescriptorSetLayout(device_, set_layout_, nullptr);
            for (Image& image : ring_) destroy_image(image);
            destroy_image(depth_);
            auto destroy_buffer = [&](VkBuffer buffer, Allocation& allocation) {
                fn_.vkDestroyBuffer(device_, buffer, nullptr);
                fn_.vkFreeMemory(device_, allocation.memory, nullptr);  // unmaps implicitly
            };
            destroy_buffer(mesh_.positions, mesh_.positions_memory);
            destroy_buffer(mesh_.normals, mesh_.normals_memory);
            destroy_buffer(mesh_.indices, mesh_.indices_memory);
            destroy_buffer(uniform_buffer_, uniform_);
            destroy_buffer(readback_buffer_, readback_);
            fn_.vkDestroyDevice(device_, nullptr);
        }
        if (window_sc_.surface)
            vkDestroySurfaceKHR(instance_, window_sc_.surface, nullptr);  // before the window (a member) goes
        if (messenger_) {
            auto destroy_messenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
                vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
            destroy_messenger(instance_, messenger_, nullptr);
        }
        if (instance_) vkDestroyInstance(instance_, nullptr);
    }

    Config config_;
    CameraUniforms camera_{};
    std::vector<PushConstants> draws_;
    ThreadPool* recorders_ = nullptr;  // --threads N > 1

    BenchWindow window_;  // windowed only; outlives the surface (destroy() runs first)
    VkInstance instance_ = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    VkPhysicalDevice physical_device_ = VK_NULL_HANDLE;
    VkPhysicalDeviceMemoryProperties memory_properties_{};
    std::string device_name_;
    VkDeviceSize uniform_alignment_ = 1;
    std::uint32_t queue_family_ = 0;
    VkDevice device_ = VK_NULL_HANDLE;
    DeviceFunctions fn_;
    VkQueue queue_ = VK_NULL_HANDLE;

    MeshBuffers mesh_;
    VkBuffer uniform_buffer_ = VK_NULL_HANDLE;
    Allocation uniform_;
    VkDeviceSize uniform_stride_ = 0;
    VkBuffer readback_buffer_ = VK_NULL_HANDLE;
    Allocation readback_;
    std::vector<Image> ring_;
    Image depth_;
    VkExtent2D depth_extent_{};
    VkFormat colour_format_ = colour_format;  // windowed: the swapchain's

    WindowSwapchain window_sc_;       // windowed only
    bool present_to_window_ = false;  // windowed, except for the reference frame
    VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
    VkPipelineLayout pipeline_layout_ = VK_NULL_HANDLE;
    VkPipeline pipeline_ = VK_NULL_HANDLE;
    VkDescriptorPool descriptor_pool_ = VK_NULL_HANDLE;
    std::vector<Frame> frames_;

    std::uint64_t frame_ = 0;
    std::uint32_t slot_ = 0;
    std::uint32_t image_ = 0;
    std::uint32_t presented_image_ = 0;
    Target target_;
};

}  // namespace

std::unique_ptr<Variant> make_raw_variant() { return std::make_unique<RawVariant<false>>(); }
std::unique_ptr<Variant> make_raw_direct_variant() { return std::make_unique<RawVariant<true>>(); }

}  // namespace teapot
