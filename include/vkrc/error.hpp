// Errors: failed Vulkan calls throw; statuses that are not failures return.
#pragma once

#include "vkrc/config.hpp"

#include <vulkan/vulkan_core.h>

#include <stdexcept>
#include <string>
#include <system_error>

VKRC_BEGIN_NAMESPACE

// The std::error_category of VkResult values.
const std::error_category& vk_result_category() noexcept;
std::error_code make_error_code(VkResult result) noexcept;
// "VK_ERROR_DEVICE_LOST"; nullptr for a value this build does not know.
const char* to_string(VkResult result) noexcept;

// A Vulkan call returned a negative VkResult. what() names the call and the result.
class Error : public std::system_error {
public:
    Error(VkResult result, const char* call);
    VkResult result() const noexcept { return static_cast<VkResult>(code().value()); }
    const char* call() const noexcept { return call_; }

private:
    const char* call_;  // a string literal naming the Vulkan function
};

// VK_ERROR_DEVICE_LOST: the device is gone; every handle can still be dropped.
class DeviceLostError : public Error {
public:
    explicit DeviceLostError(const char* call) : Error(VK_ERROR_DEVICE_LOST, call) {}
};

// The application passed something vkrc can tell is wrong before Vulkan sees
// it (bad SPIR-V, an overflowing size, a write past a mapping, ...).
class UsageError : public std::invalid_argument {
public:
    using std::invalid_argument::invalid_argument;
};

namespace detail {
[[noreturn]] void throw_vk_error(VkResult result, const char* call);
}

// Throws Error (DeviceLostError for VK_ERROR_DEVICE_LOST) when result is a
// failure; returns it otherwise so callers can branch on VK_TIMEOUT,
// VK_NOT_READY, VK_SUBOPTIMAL_KHR and friends.
inline VkResult check(VkResult result, const char* call) {
    if (result < 0) [[unlikely]] {
        detail::throw_vk_error(result, call);
    }
    return result;
}

VKRC_END_NAMESPACE
