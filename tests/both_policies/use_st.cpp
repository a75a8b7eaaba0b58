#include <vkrc/vkrc.hpp>

#include <string>

// Built against vkrc::st; the inline namespace keeps its symbols apart from vkrc::mt's.
std::string use_single_thread_policy() {
    auto instance = vkrc::Instance::create();
    auto device = vkrc::Device::create(vkrc::PhysicalDevice::select(instance));
    static_assert(!vkrc::ThreadPolicy::multi_thread);
    return device ? "vkrc::st::Device ok" : "failed";
}
