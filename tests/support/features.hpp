// For tests that need a device with optional features (the test skips,
// naming what is missing, where the driver lacks them), and a one-shot
// command buffer to run their work.
#pragma once

#include <vkrc/vkrc.hpp>

#include <gtest/gtest.h>

#include <initializer_list>
#include <span>
#include <string>
#include <utility>

namespace vkrc_test {

// What the physical device supports, core and per Vulkan version.
struct SupportedFeatures {
    VkPhysicalDeviceVulkan11Features v11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
    VkPhysicalDeviceVulkan12Features v12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    VkPhysicalDeviceVulkan13Features v13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    VkPhysicalDeviceFeatures2 core{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
};

inline SupportedFeatures supported_features(const vkrc::PhysicalDevice& physical_device) {
    SupportedFeatures f;
    f.core.pNext = &f.v11;
    f.v11.pNext = &f.v12;
    f.v12.pNext = &f.v13;
    physical_device.fn().vkGetPhysicalDeviceFeatures2(physical_device.vk(), &f.core);
    f.v11.pNext = f.v12.pNext = f.v13.pNext = nullptr;  // DeviceCreateInfo takes copies and chains them itself
    return f;
}

// The message of the UsageError f throws, or "(no UsageError)".
std::string usage_error_of(auto&& f) {
    try {
        f();
    } catch (const vkrc::UsageError& e) {
        return e.what();
    }
    return "(no UsageError)";
}

// unmet_requirements of wanted, which asks for one feature more than the
// test device's defaults: nothing where the device has it (supported), else
// exactly the reason given.
inline void expect_requirement_named(const vkrc::PhysicalDevice& physical, const vkrc::DeviceRequirements& wanted,
                                     bool supported, const char* reason) {
    const auto unmet = physical.unmet_requirements(wanted);
    if (supported) {
        EXPECT_TRUE(unmet.empty());
        return;
    }
    ASSERT_EQ(unmet.size(), 1u);
    EXPECT_STREQ(unmet[0].c_str(), reason);
}

// The names of the features that are VK_FALSE, comma-separated; empty when all are there.
inline std::string missing_features(std::initializer_list<std::pair<const char*, VkBool32>> features) {
    std::string out;
    for (const auto& [name, supported] : features) {
        if (supported) continue;
        if (!out.empty()) out += ", ";
        out += name;
    }
    return out;
}

// A primary command buffer, recording from construction; run() submits it and waits.
struct OneShotCommands {
    vkrc::CommandPool pool;
    vkrc::CommandBuffer cmd;
    explicit OneShotCommands(const vkrc::Queue& queue)
        : pool(vkrc::CommandPool::create(queue.device(), {.queue_family_index = queue.family_index()})),
          cmd(pool.allocate()) {
        cmd.begin();
    }
    void run(const vkrc::Queue& queue) const {
        cmd.end();
        auto fence = vkrc::Fence::create(queue.device());
        vkrc::submit(queue, {.command_buffers = std::span(&cmd, 1)}, fence);
        ASSERT_EQ(fence.wait(), VK_SUCCESS);
    }
};

// A one-subpass render pass over one colour attachment of format: cleared,
// stored and left in TRANSFER_SRC_OPTIMAL, its writes and final transition
// made visible to a copy after the pass.
inline vkrc::RenderPass clear_to_copy_render_pass(const vkrc::Device& device, VkFormat format) {
    const VkAttachmentDescription color{0,
                                        format,
                                        VK_SAMPLE_COUNT_1_BIT,
                                        VK_ATTACHMENT_LOAD_OP_CLEAR,
                                        VK_ATTACHMENT_STORE_OP_STORE,
                                        VK_ATTACHMENT_LOAD_OP_DONT_CARE,
                                        VK_ATTACHMENT_STORE_OP_DONT_CARE,
                                        VK_IMAGE_LAYOUT_UNDEFINED,
                                        VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
    const VkSubpassDependency to_copy{0,
                                      VK_SUBPASS_EXTERNAL,
                                      VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                                      VK_PIPELINE_STAGE_TRANSFER_BIT,
                                      VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                                      VK_ACCESS_TRANSFER_READ_BIT,
                                      0};
    return vkrc::RenderPass::create(
        device, {.attachments = {color},
                 .subpasses = {{.color_attachments = {{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL}}}},
                 .dependencies = {to_copy}});
}

// A nearest, edge-clamped sampler through conversion (Y'CbCr samplers must
// clamp to edge).
inline vkrc::Sampler ycbcr_sampler(const vkrc::Device& device, const vkrc::SamplerYcbcrConversion& conversion) {
    return vkrc::Sampler::create(device, {.mag_filter = VK_FILTER_NEAREST,
                                          .min_filter = VK_FILTER_NEAREST,
                                          .mipmap_mode = VK_SAMPLER_MIPMAP_MODE_NEAREST,
                                          .address_mode_u = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
                                          .address_mode_v = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
                                          .address_mode_w = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
                                          .ycbcr_conversion = conversion});
}

// A barrier making compute shader writes visible to host reads.
inline VkMemoryBarrier2 compute_to_host() {
    return vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
}

// Records a copy of the whole colour image (mip 0, layer 0, in
// TRANSFER_SRC_OPTIMAL) into buffer, tightly packed, and the barrier that
// makes it visible to host reads.
inline void record_readback(const vkrc::CommandBuffer& cmd, VkImage image, VkBuffer buffer, std::uint32_t width,
                            std::uint32_t height) {
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {width, height, 1};
    cmd.copy_image_to_buffer(image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer, std::span(&region, 1));
    const auto to_host = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                              VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
}

// A 1x1 R32_UINT image holding value: cleared by cmd and left in layout for
// any later read (usage gets TRANSFER_DST added).
inline vkrc::Image uint_image(const vkrc::Device& device, const vkrc::CommandBuffer& cmd, std::uint32_t value,
                              VkImageUsageFlags usage, VkImageLayout layout) {
    auto image =
        vkrc::Image::create(device, {.format = VK_FORMAT_R32_UINT, .usage = usage | VK_IMAGE_USAGE_TRANSFER_DST_BIT});
    auto to_dst = vkrc::image_barrier(image.vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                      VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE, VK_PIPELINE_STAGE_2_CLEAR_BIT,
                                      VK_ACCESS_2_TRANSFER_WRITE_BIT);
    cmd.pipeline_barrier({}, {}, std::span(&to_dst, 1));
    VkClearColorValue color{};
    color.uint32[0] = value;
    const VkImageSubresourceRange whole{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    cmd.clear_color_image(image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, color, std::span(&whole, 1));
    auto to_read = vkrc::image_barrier(image.vk(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, layout,
                                       VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                       VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_READ_BIT);
    cmd.pipeline_barrier({}, {}, std::span(&to_read, 1));
    return image;
}

}  // namespace vkrc_test
