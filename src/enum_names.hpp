// Vulkan names of the enums that UsageError messages print (not installed).
#pragma once

#include "vkrc/error.hpp"

#include <string>

VKRC_BEGIN_NAMESPACE
namespace detail {

// The value's Vulkan name (VK_DESCRIPTOR_TYPE_STORAGE_BUFFER), or the type and
// number (VkFormat(1000156000)) for a value the table lacks. Defined in
// error.cpp from the table scripts/gen_enum_names.py generates.
std::string enum_text(VkDescriptorType value);
std::string enum_text(VkFormat value);
std::string enum_text(VkPhysicalDeviceType value);
std::string enum_text(VkColorSpaceKHR value);
std::string enum_text(VkImageLayout value);
std::string enum_text(VkImageType value);
std::string enum_text(VkImageTiling value);
std::string enum_text(VkImageViewType value);
std::string enum_text(VkSampleCountFlagBits value);
std::string enum_text(VkSamplerAddressMode value);
std::string enum_text(VkFilter value);
std::string enum_text(VkSamplerMipmapMode value);

}  // namespace detail
VKRC_END_NAMESPACE
