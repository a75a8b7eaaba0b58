#include "text.hpp"

#include <algorithm>
#include <cstring>

VKRC_BEGIN_NAMESPACE
namespace detail {

bool contains(Span<const Text> names, const char* name) noexcept {
    return std::find(names.begin(), names.end(), name) != names.end();
}

bool contains(Span<const char* const> names, const char* name) noexcept {
    return std::any_of(names.begin(), names.end(), [&](const char* n) { return std::strcmp(n, name) == 0; });
}

std::string hex(std::uint64_t v, std::size_t digits) {
    static const char symbols[] = "0123456789abcdef";
    std::string s;
    do {
        s.insert(s.begin(), symbols[v & 15]);
        v >>= 4;
    } while (v || s.size() < digits);
    return s;
}

}  // namespace detail
VKRC_END_NAMESPACE
