// Foundation helpers on names and numbers, shared by every layer (not installed).
#pragma once

#include "vkrc/error.hpp"

#include <cstdint>
#include <span>
#include <string>
#include <vector>

VKRC_BEGIN_NAMESPACE
namespace detail {

// Whether a list of extension or layer names holds name.
bool contains(std::span<const Text> names, const char* name) noexcept;
bool contains(std::span<const char* const> names, const char* name) noexcept;
// Adds name to a list of extension or layer names unless it is there.
void add_unique(std::vector<const char*>& names, const char* name);
// The lower-case hexadecimal digits of v, without a prefix.
std::string hex(std::uint64_t v);

}  // namespace detail
VKRC_END_NAMESPACE
