// Creates a device through an installed or embedded vkrc and names it, with
// the thread policy this program was compiled for.
#include <vkrc/vkrc.hpp>

#include <cstdio>
#include <exception>

int main() try {
    vkrc::Instance instance = vkrc::Instance::create({.application_name = "vkrc consumer"});
    vkrc::PhysicalDevice gpu = vkrc::PhysicalDevice::select(instance);
    vkrc::Device device = vkrc::Device::create(gpu);
    std::printf("vkrc consumer (policy %s): %s\n", VKRC_IS_MULTI_THREAD ? "mt" : "st", device.physical_device().name());
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "vkrc consumer: %s\n", e.what());
    return 1;
}
