// Blocking staging transfers: uploads into buffers and images (every mip
// level and array layer, with the layout transitions) and downloads for
// reading back. Each call is an Uploader's (vkrc/stream.hpp) upload or
// download on the queue followed by a wait for its ticket: the simple path,
// for loading and for tests, not per frame.
#pragma once

#include "vkrc/stream.hpp"

#include "vkrc/detail/list.hpp"

VKRC_BEGIN_NAMESPACE

// Copies data to buffer at offset through a staging buffer. The buffer needs
// VK_BUFFER_USAGE_TRANSFER_DST_BIT. The copy waits for earlier submissions on
// the queue to finish with the buffer; later submits on any queue see the data.
void upload_buffer(const Queue& queue, const Buffer& buffer, VkDeviceSize offset, Span<const std::byte> data);

// Copies size bytes at offset out of buffer (needs VK_BUFFER_USAGE_TRANSFER_SRC_BIT).
List<std::byte> download_buffer(const Queue& queue, const Buffer& buffer, VkDeviceSize offset, VkDeviceSize size);

// Fills every mip level and array layer of a colour image (needs
// VK_IMAGE_USAGE_TRANSFER_DST_BIT) from data laid out as image_data_size says.
void upload_image(const Queue& queue, const Image& image, Span<const std::byte> data, const ImageUploadInfo& info = {});

// Copies one mip level of one array layer of a colour image (needs
// VK_IMAGE_USAGE_TRANSFER_SRC_BIT), tightly packed. The image is in layout
// and is left in it.
List<std::byte> download_image(const Queue& queue, const Image& image, VkImageLayout layout,
                               std::uint32_t mip_level = 0, std::uint32_t array_layer = 0);

VKRC_END_NAMESPACE
