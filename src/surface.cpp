#include "vkrc/surface.hpp"

#include "object_state.hpp"
#include "text.hpp"

#include <vector>

VKRC_BEGIN_NAMESPACE

namespace detail {
SurfaceState::~SurfaceState() {
    // Swapchains hold the surface until their deferred destruction has run,
    // so none is left when this runs.
    if (owns_handle()) instance.fn().vkDestroySurfaceKHR(instance.vk(), handle, nullptr);
}
}  // namespace detail

Surface Surface::adopt(const Instance& instance, VkSurfaceKHR surface, Ownership ownership) {
    const detail::Caller caller{"vkrc::Surface::adopt"};
    caller.require(!instance || instance.extension_enabled(VK_KHR_SURFACE_EXTENSION_NAME),
                   "the instance was created without VK_KHR_surface");
    return Surface(detail::adopted_state<detail::SurfaceState, &detail::SurfaceState::instance>(
        caller, instance, "the Instance", surface, "VkSurfaceKHR", ownership));
}

VkSurfaceCapabilitiesKHR Surface::capabilities(const PhysicalDevice& physical_device) const {
    VkSurfaceCapabilitiesKHR caps{};
    check(instance().fn().vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical_device.vk(), vk(), &caps),
          "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
    return caps;
}

List<VkSurfaceFormatKHR> Surface::formats(const PhysicalDevice& physical_device) const {
    return detail::enumerate<VkSurfaceFormatKHR>(instance().fn().vkGetPhysicalDeviceSurfaceFormatsKHR,
                                                 "vkGetPhysicalDeviceSurfaceFormatsKHR", physical_device.vk(), vk());
}

List<VkPresentModeKHR> Surface::present_modes(const PhysicalDevice& physical_device) const {
    return detail::enumerate<VkPresentModeKHR>(instance().fn().vkGetPhysicalDeviceSurfacePresentModesKHR,
                                               "vkGetPhysicalDeviceSurfacePresentModesKHR", physical_device.vk(), vk());
}

VKRC_END_NAMESPACE
