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

// A barrier making compute shader writes visible to host reads.
inline VkMemoryBarrier2 compute_to_host() {
    return vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
}

}  // namespace vkrc_test
