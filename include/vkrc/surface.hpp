// Presentation surfaces (VK_KHR_surface).
//
// vkrc's core never depends on a window system: a Surface adopts a
// VkSurfaceKHR made by whatever created the window. vkrc/glfw.hpp (the
// vkrc::glfw libraries) makes one from a GLFW window.
#pragma once

#include "vkrc/instance.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
class SurfaceState;
}  // namespace detail

// A surface; keeps its Instance alive. At most one Swapchain uses it at a
// time (Swapchain::create takes it); swapchains retired by re-creation keep
// it alive until the GPU and the presentation engine are done with them.
class Surface : public VulkanObject<detail::SurfaceState, VkSurfaceKHR> {
public:
    // Wraps a surface made for instance. With Ownership::owned vkrc destroys
    // it (vkDestroySurfaceKHR) when the last owner goes.
    static Surface adopt(const Instance& instance, VkSurfaceKHR surface, Ownership ownership);

    const Instance& instance() const VKRC_UNCHECKED_NOEXCEPT;
    // vkGetPhysicalDeviceSurfaceCapabilitiesKHR.
    VkSurfaceCapabilitiesKHR capabilities(const PhysicalDevice& physical_device) const;
    // vkGetPhysicalDeviceSurfaceFormatsKHR / PresentModesKHR.
    List<VkSurfaceFormatKHR> formats(const PhysicalDevice& physical_device) const;
    List<VkPresentModeKHR> present_modes(const PhysicalDevice& physical_device) const;

private:
    using VulkanObject::VulkanObject;
};

namespace detail {

class SurfaceState final : public VulkanObjectState<VkSurfaceKHR> {
public:
    static constexpr const char* type_name = "vkrc::Surface";
    ~SurfaceState() override;
    Instance instance;
    // Vulkan allows one non-retired swapchain per surface. taken: a live
    // Swapchain holds the surface. releasing: the last one is gone but its
    // current Vulkan swapchain is not destroyed yet (frames hold its images,
    // or the GPU is not done). Both under mutex.
    bool taken = false;
    bool releasing = false;
    Mutex mutex;
};

}  // namespace detail

inline const Instance& Surface::instance() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::Surface::instance").instance;
}

VKRC_END_NAMESPACE
