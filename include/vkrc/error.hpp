// Errors: failed Vulkan calls throw; statuses that are not failures return.
//
// vkrc's exceptions derive from std::exception and keep their messages in a
// vkrc::Text: <stdexcept> and <system_error> bring in <string>, which every
// translation unit that includes vkrc would parse (bench/header_cost). Even
// <exception> brings <type_traits> (exception_ptr, nested exceptions), most
// of what vkrc's headers cost; <new> defines std::bad_alloc, a
// std::exception, so it declares std::exception completely at a third of
// the price.
#pragma once

#include "vkrc/config.hpp"
#include "vkrc/detail/moves.hpp"

#include <vulkan/vulkan_core.h>

#include <cstddef>
#include <new>  // std::exception (see above)

VKRC_BEGIN_NAMESPACE

// An immutable, shared, null-terminated string: the messages and reports vkrc
// hands out (error messages, rejection reasons, layer and extension names).
// Copying shares the characters and cannot throw, as exceptions require.
class Text {
public:
    Text() noexcept = default;
    Text(const char* text);  // copies; null means empty
    Text(const char* data, std::size_t size);
    // Any string type with c_str() (std::string), without <string> here.
    template <class String>
    requires requires(const String& s) { s.c_str(); }
    explicit Text(const String& text) : Text(text.c_str()) {}
    Text(const Text& other) noexcept;
    Text(Text&& other) noexcept : block_(moves::take(other.block_)) {}
    Text& operator=(Text other) noexcept {
        moves::swap_values(block_, other.block_);
        return *this;
    }
    ~Text();

    const char* c_str() const noexcept;
    std::size_t size() const noexcept;
    bool empty() const noexcept { return size() == 0; }
    // Whether part occurs in the text.
    bool contains(const char* part) const noexcept;
    friend bool operator==(const Text& a, const char* b) noexcept;
    friend bool operator==(const Text& a, const Text& b) noexcept { return a == b.c_str(); }

private:
    struct Block;
    Block* block_ = nullptr;
};

// "VK_ERROR_DEVICE_LOST"; nullptr for a value this build does not know.
const char* to_string(VkResult result) noexcept;

// A Vulkan call returned a negative VkResult. what() names the call and the
// result: "vkAllocateMemory failed: VK_ERROR_OUT_OF_DEVICE_MEMORY".
class Error : public std::exception {
public:
    Error(VkResult result, const char* call);
    VkResult result() const noexcept { return result_; }
    const char* call() const noexcept { return call_; }
    const char* what() const noexcept override { return what_.c_str(); }

private:
    VkResult result_;
    const char* call_;  // a string literal naming the Vulkan function
    Text what_;
};

// VK_ERROR_DEVICE_LOST: the device is gone; every handle can still be dropped.
class DeviceLostError : public Error {
public:
    explicit DeviceLostError(const char* call) : Error(VK_ERROR_DEVICE_LOST, call) {}
};

// The application passed something vkrc can tell is wrong before Vulkan sees
// it (bad SPIR-V, an overflowing size, a write past a mapping, ...).
class UsageError : public std::exception {
public:
    explicit UsageError(const char* message) : what_(message) {}
    // Any string type with c_str() (std::string), without <string> here.
    template <class String>
    requires requires(const String& s) { s.c_str(); }
    explicit UsageError(const String& message) : what_(message.c_str()) {}
    const char* what() const noexcept override { return what_.c_str(); }

private:
    Text what_;
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
