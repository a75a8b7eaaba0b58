// The blocking helpers: thin wrappers over the Uploader's one path
// (staging.hpp): a one-time Uploader, one recording, a wait.
#include "vkrc/upload.hpp"

#include "staging.hpp"

VKRC_BEGIN_NAMESPACE

void upload_buffer(const Queue& queue, const Buffer& buffer, VkDeviceSize offset, Span<const std::byte> data) {
    const detail::Caller caller{"vkrc::upload_buffer"};
    Uploader uploader = detail::one_time_uploader(queue, data.size(), caller);
    detail::record_upload(*uploader.state(), buffer, offset, data, caller);
    uploader.submit().wait_on_host();
}

List<std::byte> download_buffer(const Queue& queue, const Buffer& buffer, VkDeviceSize offset, VkDeviceSize size) {
    const detail::Caller caller{"vkrc::download_buffer"};
    Uploader uploader = detail::one_time_uploader(queue, 1, caller);
    if (size == 0) return {};
    const Download download = detail::record_download(*uploader.state(), buffer, offset, size, caller);
    uploader.submit();
    return download.read();
}

void upload_image(const Queue& queue, const Image& image, Span<const std::byte> data, const ImageUploadInfo& info) {
    const detail::Caller caller{"vkrc::upload_image"};
    Uploader uploader = detail::one_time_uploader(queue, data.size(), caller);
    detail::record_upload(*uploader.state(), image, data, info, caller);
    uploader.submit().wait_on_host();
}

List<std::byte> download_image(const Queue& queue, const Image& image, VkImageLayout layout, std::uint32_t mip_level,
                               std::uint32_t array_layer) {
    const detail::Caller caller{"vkrc::download_image"};
    Uploader uploader = detail::one_time_uploader(queue, 1, caller);
    const Download download = detail::record_download(*uploader.state(), image, layout, mip_level, array_layer, caller);
    uploader.submit();
    return download.read();
}

VKRC_END_NAMESPACE
