// Staging transfers: uploads into buffers and images (every mip level and
// array layer, with the layout transitions) and downloads for reading back.
// Each call is an Uploader's (vkrc/stream.hpp) upload or download on the
// queue followed by a wait for its ticket: the simple path, for loading and
// for tests, not per frame.
#pragma once

#include "vkrc/resource.hpp"

#include "vkrc/detail/list.hpp"

VKRC_BEGIN_NAMESPACE

// Copies data to buffer at offset through a staging buffer. The buffer needs
// VK_BUFFER_USAGE_TRANSFER_DST_BIT. The copy waits for earlier submissions on
// the queue to finish with the buffer; later submits on any queue see the data.
void upload_buffer(const Queue& queue, const Buffer& buffer, VkDeviceSize offset, Span<const std::byte> data);

// Copies size bytes at offset out of buffer (needs VK_BUFFER_USAGE_TRANSFER_SRC_BIT).
List<std::byte> download_buffer(const Queue& queue, const Buffer& buffer, VkDeviceSize offset, VkDeviceSize size);

// Every member is optional.
struct ImageUploadInfo {
    // The image's layout before the upload; UNDEFINED (the default) discards its contents.
    VkImageLayout old_layout = VK_IMAGE_LAYOUT_UNDEFINED;
    // The layout the image is left in, for the work that reads it next (default shader read-only).
    VkImageLayout new_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    // The levels uploaded, from level 0 (default all). Fewer, e.g. level 0
    // alone for generate_mipmaps to fill the rest on the GPU: the data then
    // holds just those levels, and the others are left in new_layout with
    // undefined contents. Must be 1 to the image's mip_levels.
    std::uint32_t level_count = VK_REMAINING_MIP_LEVELS;
};

// Bytes upload_image expects: every mip level of every array layer, tightly
// packed (block-compressed levels in whole blocks, rounded up), level by level and within a level layer by layer (level 0 layer 0,
// level 0 layer 1, ..., level 1 layer 0, ...). With level_count, only the
// first level_count levels (ImageUploadInfo::level_count); UsageError when
// it is 0 or more than the image has.
VkDeviceSize image_data_size(const Image& image, std::uint32_t level_count = VK_REMAINING_MIP_LEVELS);

// Fills every mip level and array layer of a colour image (needs
// VK_IMAGE_USAGE_TRANSFER_DST_BIT) from data laid out as image_data_size says.
void upload_image(const Queue& queue, const Image& image, Span<const std::byte> data, const ImageUploadInfo& info = {});

// Copies one mip level of one array layer of a colour image (needs
// VK_IMAGE_USAGE_TRANSFER_SRC_BIT), tightly packed. The image is in layout
// and is left in it.
List<std::byte> download_image(const Queue& queue, const Image& image, VkImageLayout layout,
                               std::uint32_t mip_level = 0, std::uint32_t array_layer = 0);

VKRC_END_NAMESPACE
