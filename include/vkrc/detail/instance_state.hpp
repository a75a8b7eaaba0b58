// State blocks behind Instance and PhysicalDevice. Included by instance.hpp.
#pragma once

#include "vkrc/instance.hpp"

VKRC_BEGIN_NAMESPACE
namespace detail {

class InstanceState final : public RefCounted {
public:
    ~InstanceState() override;

    VkInstance instance = VK_NULL_HANDLE;
    Ownership ownership = Ownership::owned;
    std::uint32_t api_version = 0;
    GlobalFunctions global_fn;
    InstanceFunctions fn;
    std::vector<Text> enabled_extensions;
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    DebugCallback debug_callback;  // the messengers' user data: the state never moves
};

class PhysicalDeviceState final : public RefCounted {
public:
    Instance instance;
    VkPhysicalDevice physical_device = VK_NULL_HANDLE;
    VkPhysicalDeviceProperties properties{};
    VkPhysicalDeviceMemoryProperties memory_properties{};
    std::vector<VkQueueFamilyProperties> queue_families;
    std::vector<Text> extensions;
};

}  // namespace detail

inline VkInstance Instance::vk() const noexcept { return state_->instance; }
inline const InstanceFunctions& Instance::fn() const noexcept { return state_->fn; }
inline const GlobalFunctions& Instance::global_fn() const noexcept { return state_->global_fn; }
inline std::uint32_t Instance::api_version() const noexcept { return state_->api_version; }

inline VkPhysicalDevice PhysicalDevice::vk() const noexcept { return state_->physical_device; }
inline const Instance& PhysicalDevice::instance() const noexcept { return state_->instance; }
inline const InstanceFunctions& PhysicalDevice::fn() const noexcept { return state_->instance.fn(); }
inline const VkPhysicalDeviceProperties& PhysicalDevice::properties() const noexcept { return state_->properties; }
inline const VkPhysicalDeviceMemoryProperties& PhysicalDevice::memory_properties() const noexcept {
    return state_->memory_properties;
}
inline const std::vector<VkQueueFamilyProperties>& PhysicalDevice::queue_families() const noexcept {
    return state_->queue_families;
}

VKRC_END_NAMESPACE
