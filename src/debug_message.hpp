// The callback of every debug-utils messenger vkrc makes (src/instance.cpp).
#pragma once

#include "vkrc/instance.hpp"

VKRC_BEGIN_NAMESPACE
namespace detail {
// Hands the message to the DebugCallback that user points to; never aborts the call.
VKAPI_ATTR VkBool32 VKAPI_CALL debug_trampoline(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                VkDebugUtilsMessageTypeFlagsEXT types,
                                                const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);
}  // namespace detail
VKRC_END_NAMESPACE
