// How vkrc refuses a bad argument (not installed): one message format,
// "who: what", where who is the public function, named once per function.
#pragma once

#include "vkrc/error.hpp"

#include "enum_names.hpp"
#include "text.hpp"

#include <cstdio>
#include <string>
#include <string_view>
#include <type_traits>

VKRC_BEGIN_NAMESPACE
namespace detail {

// One piece of a refusal's message: text as is, integers in decimal, floats
// as %g, Hex in hexadecimal, Count with "remaining", extents as WxHxD, the Vulkan enums
// enum_names.hpp knows by name. Pieces are passed by reference and formatted
// only on refusal: a piece that needs building (a std::string) is better
// built in a branch that then calls refuse().
inline void append_piece(std::string& out, std::string_view text) { out += text; }
template <class T>
concept decimal_number = std::is_integral_v<T> && !std::is_same_v<T, bool>;
template <class T>
concept named_enum = std::is_enum_v<T> && requires(T e) {
    enum_text(e);
};
template <decimal_number Integer>
void append_piece(std::string& out, Integer n) {
    out += std::to_string(n);
}
template <named_enum Enum>
void append_piece(std::string& out, Enum e) {
    out += enum_text(e);
}
// Floats as printf's %g prints them (0.5, 16, 1e+03).
inline void append_piece(std::string& out, double x) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", x);
    out += text;
}
// A number shown in hexadecimal with a 0x prefix (flags and bit masks):
// caller.require(ok, "flags ", Hex{flags}).
struct Hex {
    std::uint64_t value;
};
inline void append_piece(std::string& out, Hex h) {
    out += "0x";
    out += hex(h.value);
}

// A level or layer count that may be VK_REMAINING_MIP_LEVELS or
// VK_REMAINING_ARRAY_LAYERS (both ~0U): "remaining", else the number.
struct Count {
    std::uint32_t value;
};
inline void append_piece(std::string& out, Count c) {
    out += c.value == VK_REMAINING_MIP_LEVELS ? std::string("remaining") : std::to_string(c.value);
}
// An extent as WxHxD.
inline void append_piece(std::string& out, const VkExtent3D& e) {
    out += std::to_string(e.width) + "x" + std::to_string(e.height) + "x" + std::to_string(e.depth);
}

// Throws UsageError "name: about: what..." (about may be null). Out of line,
// cold and given the names by value, so a passing check on a per-frame path
// (present, submit) costs its compare and branch: no Caller is put in memory.
template <class... What>
[[noreturn, gnu::noinline, gnu::cold]] void refuse_as(const char* name, const char* about, const What&... what) {
    std::string message(name);
    message += ": ";
    if (about) {
        message += about;
        message += ": ";
    }
    (append_piece(message, what), ...);
    throw UsageError(message);
}

// The public function that checks its arguments. Usage, once per function:
//     const detail::Caller caller{"vkrc::DescriptorPool::create"};
//     caller.require(info.max_sets != 0, "max_sets is 0");
//     caller.require(n <= max, "count ", n, " exceeds ", max);
// The pieces are formatted only when the check fails, so a passing check
// costs its condition alone.
class Caller {
public:
    explicit constexpr Caller(const char* name) noexcept : name_(name) {}
    // The same for a function working on one named thing, e.g. a file: its
    // refusals read "name: about: what". about must outlive the Caller.
    constexpr Caller(const char* name, const char* about) noexcept : name_(name), about_(about) {}
    const char* name() const noexcept { return name_; }

    // Throws UsageError "name: what..." unless ok.
    template <class... What>
    void require(bool ok, const What&... what) const {
        if (!ok) [[unlikely]]
            refuse(what...);
    }
    template <class... What>
    [[noreturn]] void refuse(const What&... what) const {
        refuse_as(name_, about_, what...);
    }
    // "name: the_name handle is empty", the_name saying which (e.g. "the
    // Device", "a ShaderModule").
    template <class Handle>
    void require_handle(const Handle& handle, const char* the_name) const {
        require(static_cast<bool>(handle), the_name, " handle is empty");
    }
    // "name: the handle_name is VK_NULL_HANDLE" (e.g. "VkDevice").
    template <class VkHandle>
    void require_not_null(VkHandle handle, const char* handle_name) const {
        require(handle != VK_NULL_HANDLE, "the ", handle_name, " is VK_NULL_HANDLE");
    }

private:
    const char* name_;
    const char* about_ = nullptr;
};

}  // namespace detail
VKRC_END_NAMESPACE
