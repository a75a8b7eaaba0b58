// For the acceleration-structure tests: a device with ray queries (or what
// the physical device lacks for one) and a fixture with it, build inputs,
// transforms and the barriers after builds.
#pragma once

#include "support/vk_test.hpp"

#include <span>
#include <string>
#include <vector>

namespace vkrc_test {

constexpr VkBufferUsageFlags build_input_usage =
    VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT | VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;

// What physical lacks for acceleration structures traced by ray queries, as
// select() names it ("lacks feature rayQuery (VK_KHR_ray_query)"); empty
// when it has all of it.
inline std::string ray_query_unmet(const vkrc::PhysicalDevice& physical) {
    vkrc::DeviceRequirements wanted = test_device_requirements();
    wanted.required_features.acceleration_structure.accelerationStructure = VK_TRUE;
    wanted.required_features.ray_query.rayQuery = VK_TRUE;
    wanted.required_features.vulkan12.bufferDeviceAddress = VK_TRUE;
    const auto unmet = physical.unmet_requirements(wanted);
    return unmet.empty() ? std::string() : std::string(unmet[0].c_str());
}

// A device with accelerationStructure, rayQuery and bufferDeviceAddress
// (check ray_query_unmet first).
inline vkrc::Device ray_query_device(const vkrc::PhysicalDevice& physical) {
    vkrc::DeviceCreateInfo info;
    info.acceleration_structure_features.accelerationStructure = VK_TRUE;  // enables the extensions
    info.ray_query_features.rayQuery = VK_TRUE;
    info.vulkan12_features.bufferDeviceAddress = VK_TRUE;
    return vkrc::Device::create(physical, info);
}

// Fixture: VulkanTest's, with the device replaced by ray_query_device's;
// skipped, naming what is missing, where the physical device lacks it.
class RayQueryTest : public VulkanTest {
protected:
    void SetUp() override {
        VulkanTest::SetUp();
        if (HasFatalFailure() || IsSkipped()) return;
        const std::string unmet = ray_query_unmet(physical_device);
        if (!unmet.empty()) GTEST_SKIP() << "the device " << unmet;
        device = ray_query_device(physical_device);
        queue = device.default_queue();
    }
};

// A host-written buffer a build reads by device address.
template <class T>
vkrc::Buffer build_input(const vkrc::Device& device, const std::vector<T>& values) {
    auto buffer = vkrc::Buffer::create(device, {.size = values.size() * sizeof(T),
                                                .usage = build_input_usage,
                                                .memory = {.usage = vkrc::MemoryUsage::upload}});
    buffer.allocation().write(0, values.data(), values.size());
    return buffer;
}

// A translation (and uniform scale) as a VkTransformMatrixKHR.
inline VkTransformMatrixKHR placed(float x, float y, float z, float scale = 1.0f) {
    return {{{scale, 0, 0, x}, {0, scale, 0, y}, {0, 0, scale, z}}};
}

// A barrier from acceleration structure builds to what reads the structures at stage.
inline VkMemoryBarrier2 built_to(VkPipelineStageFlags2 stage, VkAccessFlags2 access) {
    return vkrc::memory_barrier(VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                                VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR, stage, access);
}

// A barrier from bottom-level builds to the top-level build that reads them.
inline void barrier_between_levels(const vkrc::CommandBuffer& cmd) {
    const auto b = built_to(VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                            VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR);
    cmd.pipeline_barrier(std::span(&b, 1), {}, {});
}

}  // namespace vkrc_test
