// Foundation helpers on names and numbers, shared by every layer (not installed).
#pragma once

#include "vkrc/error.hpp"

#include "vkrc/detail/span.hpp"

#include <cstdint>
#include <string>
#include <vector>

VKRC_BEGIN_NAMESPACE
namespace detail {

// Whether a list of extension or layer names holds name.
bool contains(Span<const Text> names, const char* name) noexcept;
bool contains(Span<const char* const> names, const char* name) noexcept;
// Adds name to a list of extension or layer names (std::vector or List)
// unless it is there.
template <class Names>
void add_unique(Names& names, const char* name) {
    if (!contains(names, name)) names.push_back(name);
}
// The lower-case hexadecimal digits of v, without a prefix, zero-padded to
// at least digits.
std::string hex(std::uint64_t v, std::size_t digits = 1);

// Vulkan's two-call enumeration: call(&count, nullptr), then call(&count,
// data) until it stops returning VK_INCOMPLETE; what names the function.
template <class T, class F>
std::vector<T> enumerate(F&& call, const char* what) {
    std::uint32_t count = 0;
    std::vector<T> items;
    VkResult r;
    do {
        check(call(&count, nullptr), what);
        items.resize(count);
        r = check(call(&count, items.data()), what);
    } while (r == VK_INCOMPLETE);
    items.resize(count);
    return items;
}

// The same for a Vulkan function that takes args... before the count and data.
template <class T, class Function, class... Args>
std::vector<T> enumerate(Function function, const char* what, Args... args) {
    return enumerate<T>([&](std::uint32_t* count, T* data) { return function(args..., count, data); }, what);
}

}  // namespace detail
VKRC_END_NAMESPACE
