// The validation callback of every variant (harness/variant.hpp), on its own
// so that programs with a subset of the variants (tests/teapot_threads_test)
// link it without the registry.
#include "harness/variant.hpp"

#include <cstdio>

namespace teapot {

VKAPI_ATTR VkBool32 VKAPI_CALL validation_callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                   VkDebugUtilsMessageTypeFlagsEXT,
                                                   const VkDebugUtilsMessengerCallbackDataEXT* data, void*) {
    ++validation_messages;
    std::fprintf(stderr, "validation %s: %s\n",
                 severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning",
                 data && data->pMessage ? data->pMessage : "(no message)");
    return VK_FALSE;
}

}  // namespace teapot
