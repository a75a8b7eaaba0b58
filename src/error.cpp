#include "vkrc/error.hpp"

#include <string>

VKRC_BEGIN_NAMESPACE

const char* to_string(VkResult result) noexcept {
    switch (result) {
#define VKRC_RESULT(name) \
    case name:            \
        return #name;
        VKRC_RESULT(VK_SUCCESS)
        VKRC_RESULT(VK_NOT_READY)
        VKRC_RESULT(VK_TIMEOUT)
        VKRC_RESULT(VK_EVENT_SET)
        VKRC_RESULT(VK_EVENT_RESET)
        VKRC_RESULT(VK_INCOMPLETE)
        VKRC_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
        VKRC_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
        VKRC_RESULT(VK_ERROR_INITIALIZATION_FAILED)
        VKRC_RESULT(VK_ERROR_DEVICE_LOST)
        VKRC_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
        VKRC_RESULT(VK_ERROR_LAYER_NOT_PRESENT)
        VKRC_RESULT(VK_ERROR_EXTENSION_NOT_PRESENT)
        VKRC_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
        VKRC_RESULT(VK_ERROR_INCOMPATIBLE_DRIVER)
        VKRC_RESULT(VK_ERROR_TOO_MANY_OBJECTS)
        VKRC_RESULT(VK_ERROR_FORMAT_NOT_SUPPORTED)
        VKRC_RESULT(VK_ERROR_FRAGMENTED_POOL)
        VKRC_RESULT(VK_ERROR_UNKNOWN)
        VKRC_RESULT(VK_ERROR_OUT_OF_POOL_MEMORY)
        VKRC_RESULT(VK_ERROR_INVALID_EXTERNAL_HANDLE)
        VKRC_RESULT(VK_ERROR_FRAGMENTATION)
        VKRC_RESULT(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
        VKRC_RESULT(VK_PIPELINE_COMPILE_REQUIRED)
        VKRC_RESULT(VK_ERROR_SURFACE_LOST_KHR)
        VKRC_RESULT(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR)
        VKRC_RESULT(VK_SUBOPTIMAL_KHR)
        VKRC_RESULT(VK_ERROR_OUT_OF_DATE_KHR)
        VKRC_RESULT(VK_ERROR_INCOMPATIBLE_DISPLAY_KHR)
        VKRC_RESULT(VK_ERROR_VALIDATION_FAILED_EXT)
        VKRC_RESULT(VK_ERROR_INVALID_SHADER_NV)
        VKRC_RESULT(VK_ERROR_FULL_SCREEN_EXCLUSIVE_MODE_LOST_EXT)
#undef VKRC_RESULT
        default:
            return nullptr;
    }
}

namespace {
class VkResultCategory final : public std::error_category {
public:
    const char* name() const noexcept override { return "VkResult"; }
    std::string message(int value) const override {
        const char* name = vkrc::to_string(static_cast<VkResult>(value));
        return name ? name : "VkResult(" + std::to_string(value) + ")";
    }
};
}  // namespace

const std::error_category& vk_result_category() noexcept {
    static const VkResultCategory category;
    return category;
}

std::error_code make_error_code(VkResult result) noexcept {
    return {static_cast<int>(result), vk_result_category()};
}

Error::Error(VkResult result, const char* call)
    : std::system_error(make_error_code(result), std::string(call) + " failed"), call_(call) {}

namespace detail {
void throw_vk_error(VkResult result, const char* call) {
    if (result == VK_ERROR_DEVICE_LOST) throw DeviceLostError(call);
    throw Error(result, call);
}
}  // namespace detail

VKRC_END_NAMESPACE
