// Header-cost probe: the smallest program that makes a device with vkrc.
// Compiled (not linked) by the header_cost benchmark against raii_device.cpp.
#include <vkrc/vkrc.hpp>

#include <cstdio>

int main() {
    vkrc::Instance instance = vkrc::Instance::create();
    vkrc::PhysicalDevice gpu = vkrc::PhysicalDevice::select(instance);
    vkrc::Device device = vkrc::Device::create(gpu);
    std::printf("%s\n", device.physical_device().name());
}
