// Header-cost probe: the same program as vkrc_device.cpp with Vulkan-Hpp's
// vk::raii, written as briefly as vk::raii allows.
#include <vulkan/vulkan_raii.hpp>

#include <cstdio>

int main() {
    vk::raii::Context context;
    vk::ApplicationInfo app_info("header_cost", 1, nullptr, 0, VK_API_VERSION_1_3);
    vk::raii::Instance instance(context, vk::InstanceCreateInfo({}, &app_info));
    vk::raii::PhysicalDevices gpus(instance);
    vk::raii::PhysicalDevice& gpu = gpus.front();
    const vk::QueueFlags wanted = vk::QueueFlagBits::eGraphics | vk::QueueFlagBits::eCompute;
    std::uint32_t family = 0;
    for (const vk::QueueFamilyProperties& props : gpu.getQueueFamilyProperties()) {
        if ((props.queueFlags & wanted) == wanted) break;
        ++family;
    }
    float priority = 1.0f;
    vk::DeviceQueueCreateInfo queue_info({}, family, 1, &priority);
    vk::raii::Device device(gpu, vk::DeviceCreateInfo({}, queue_info));
    std::printf("%s\n", gpu.getProperties().deviceName.data());
}
