// Vulkan names of the enums that UsageError messages print (not installed).
#pragma once

#include "vkrc/error.hpp"

#include <string>

VKRC_BEGIN_NAMESPACE
namespace detail {

// The value's Vulkan name (VK_DESCRIPTOR_TYPE_STORAGE_BUFFER), or the type and
// number (VkFormat(1000156000)) for a value the table lacks. Defined in
// error.cpp from the tables scripts/gen_enum_names.py generates.
#include "enum_text.inl"

}  // namespace detail
VKRC_END_NAMESPACE
