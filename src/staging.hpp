// The checks and sizes shared by the blocking staging functions (upload.cpp)
// and the Uploader (stream.cpp).
#pragma once

#include "vkrc/upload.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {

// The buffer or image exists, belongs to the queue's device and has the
// transfer usage (usage_name) it needs; UsageError naming who otherwise.
void check_transfer(const Queue& queue, const Buffer& buffer, VkBufferUsageFlags usage, const char* usage_name,
                    const char* who);
void check_transfer(const Queue& queue, const Image& image, VkImageUsageFlags usage, const char* usage_name,
                    const char* who);
// size bytes at offset lie in the buffer.
void check_buffer_range(const Buffer& buffer, VkDeviceSize offset, VkDeviceSize size, const char* who);
// The image's copy unit; UsageError for formats the staging code does not handle.
FormatBlock checked_block(const Image& image, const char* who);
// Bytes of one array layer of a mip level, in whole blocks.
VkDeviceSize level_size(const Image& image, std::uint32_t level, const FormatBlock& block, const char* who);
// The number of levels an upload of level_count (VK_REMAINING_MIP_LEVELS:
// all) covers; UsageError when it is 0 or more than the image has.
std::uint32_t uploaded_levels(const Image& image, std::uint32_t level_count, const char* who);
// upload_image's checks of data and info against the image.
void check_image_upload(const Image& image, Span<const std::byte> data, const ImageUploadInfo& info, const char* who);
// download_image's checks of the level, layer and layout.
void check_image_download(const Image& image, VkImageLayout layout, std::uint32_t mip_level, std::uint32_t array_layer,
                          const char* who);

}  // namespace detail

VKRC_END_NAMESPACE
