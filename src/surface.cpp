#include "vkrc/surface.hpp"
#include <vector>

#include "text.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
SurfaceState::~SurfaceState() {
    // Swapchains hold the surface until their deferred destruction has run,
    // so none is left when this runs.
    if (owns_handle()) instance.fn().vkDestroySurfaceKHR(instance.vk(), handle, nullptr);
}
}  // namespace detail

Surface Surface::adopt(const Instance& instance, VkSurfaceKHR surface, Ownership ownership) {
    if (!instance) throw UsageError("vkrc::Surface::adopt: the Instance handle is empty");
    if (surface == VK_NULL_HANDLE) throw UsageError("vkrc::Surface::adopt: the VkSurfaceKHR is VK_NULL_HANDLE");
    if (!instance.extension_enabled(VK_KHR_SURFACE_EXTENSION_NAME)) {
        throw UsageError("vkrc::Surface::adopt: the instance was created without VK_KHR_surface");
    }
    detail::Ref<detail::SurfaceState> state(new detail::SurfaceState);
    state->instance = instance;
    state->handle = surface;
    state->ownership = ownership;
    return Surface(std::move(state));
}

VkSurfaceCapabilitiesKHR Surface::capabilities(const PhysicalDevice& physical_device) const {
    VkSurfaceCapabilitiesKHR caps{};
    check(instance().fn().vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical_device.vk(), vk(), &caps),
          "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
    return caps;
}

List<VkSurfaceFormatKHR> Surface::formats(const PhysicalDevice& physical_device) const {
    const auto& fn = instance().fn();
    return detail::enumerate<VkSurfaceFormatKHR>(
        [&](std::uint32_t* n, VkSurfaceFormatKHR* p) {
            return fn.vkGetPhysicalDeviceSurfaceFormatsKHR(physical_device.vk(), vk(), n, p);
        },
        "vkGetPhysicalDeviceSurfaceFormatsKHR");
}

List<VkPresentModeKHR> Surface::present_modes(const PhysicalDevice& physical_device) const {
    const auto& fn = instance().fn();
    return detail::enumerate<VkPresentModeKHR>(
        [&](std::uint32_t* n, VkPresentModeKHR* p) {
            return fn.vkGetPhysicalDeviceSurfacePresentModesKHR(physical_device.vk(), vk(), n, p);
        },
        "vkGetPhysicalDeviceSurfacePresentModesKHR");
}

VKRC_END_NAMESPACE
