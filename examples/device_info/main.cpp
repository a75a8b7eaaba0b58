// Lists the Vulkan devices vkrc sees, why any is rejected, and which it picks.
#include <vkrc/vkrc.hpp>

#include <cstdio>

int main() try {
    vkrc::Instance instance = vkrc::Instance::create({.application_name = "device_info"});
    for (const vkrc::PhysicalDevice& device : instance.physical_devices()) {
        auto reasons = device.unmet_requirements({});
        std::printf("%s: %s\n", device.name(), reasons.empty() ? "usable" : "rejected");
        for (const auto& reason : reasons) std::printf("  - %s\n", reason.c_str());
    }
    vkrc::PhysicalDevice chosen = vkrc::PhysicalDevice::select(instance);
    vkrc::Device device = vkrc::Device::create(chosen);
    std::printf("chosen: %s, queue family %u\n", chosen.name(), device.default_queue().family_index());
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
}
