// The one transfer path (stream.cpp), as the blocking helpers (upload.cpp)
// and the Uploader's methods both call it: each records into an Uploader's
// open batch after its checks, which name the public function that caller
// gives.
#pragma once

#include "vkrc/stream.hpp"

#include "caller.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {

// Uploader::create's work, refusals named after caller.
Uploader create_uploader(const UploaderCreateInfo& info, const Caller& caller);
// The blocking helpers' Uploader: on queue, for its own family, with room
// for size bytes (at least 1), its batch ending with the copies made visible
// so that later submissions need not wait on its semaphore.
Uploader one_time_uploader(const Queue& queue, VkDeviceSize size, const Caller& caller);

// Uploader::upload_buffer, upload_image, download_buffer and download_image
// into s's open batch; caller names the refusals.
void record_upload(UploaderState& s, const Buffer& buffer, VkDeviceSize offset, Span<const std::byte> data,
                   const Caller& caller);
void record_upload(UploaderState& s, const Image& image, Span<const std::byte> data, const ImageUploadInfo& info,
                   const Caller& caller);
Download record_download(UploaderState& s, const Buffer& buffer, VkDeviceSize offset, VkDeviceSize size,
                         const Caller& caller);
Download record_download(UploaderState& s, const Image& image, VkImageLayout layout, std::uint32_t mip_level,
                         std::uint32_t array_layer, const Caller& caller);

}  // namespace detail

VKRC_END_NAMESPACE
