#include "vkrc/upload.hpp"

#include "vkrc/stream.hpp"

#include "enum_names.hpp"
#include "staging.hpp"

#include <string>
#include <type_traits>
#include <vector>

VKRC_BEGIN_NAMESPACE

namespace detail {

namespace {

template <class Resource>
void check_resource(const Queue& queue, const Resource& resource, std::uint32_t usage, const char* usage_name,
                    const char* who) {
    constexpr bool buffer = std::is_same_v<Resource, Buffer>;
    if (!resource) throw UsageError(std::string(who) + (buffer ? ": the Buffer is empty" : ": the Image is empty"));
    if (!queue) throw UsageError(std::string(who) + ": the Queue is empty");
    if (!(queue.device() == resource.device())) {
        throw UsageError(std::string(who) + ": the queue belongs to another device");
    }
    if (!(resource.usage() & usage)) {
        throw UsageError(std::string(who) + (buffer ? ": the buffer lacks " : ": the image lacks ") + usage_name);
    }
}

// a * b, or UsageError naming who when it does not fit in 64 bits.
VkDeviceSize checked_mul(VkDeviceSize a, VkDeviceSize b, const char* who) {
    VkDeviceSize r;
    if (__builtin_mul_overflow(a, b, &r)) {
        throw UsageError(std::string(who) + ": the image's size in bytes overflows 64 bits");
    }
    return r;
}

}  // namespace

void check_transfer(const Queue& queue, const Buffer& buffer, VkBufferUsageFlags usage, const char* usage_name,
                    const char* who) {
    check_resource(queue, buffer, usage, usage_name, who);
}
void check_transfer(const Queue& queue, const Image& image, VkImageUsageFlags usage, const char* usage_name,
                    const char* who) {
    check_resource(queue, image, usage, usage_name, who);
}

void check_buffer_range(const Buffer& buffer, VkDeviceSize offset, VkDeviceSize size, const char* who) {
    if (offset > buffer.size() || size > buffer.size() - offset) {
        throw UsageError(std::string(who) + ": " + std::to_string(size) + " bytes at offset " + std::to_string(offset) +
                         " do not fit in the " + std::to_string(buffer.size()) + "-byte buffer");
    }
}

FormatBlock checked_block(const Image& image, const char* who) {
    const FormatBlock block = format_block(image.format());
    if (block.bytes == 0) {
        throw UsageError(std::string(who) + ": format " + detail::enum_text(image.format()) +
                         " is neither an uncompressed colour format nor block-compressed");
    }
    if (image.samples() != VK_SAMPLE_COUNT_1_BIT) throw UsageError(std::string(who) + ": the image is multisampled");
    return block;
}

std::uint32_t uploaded_levels(const Image& image, std::uint32_t level_count, const char* who) {
    if (level_count == VK_REMAINING_MIP_LEVELS) return image.mip_levels();
    if (level_count == 0 || level_count > image.mip_levels()) {
        throw UsageError(std::string(who) + ": level_count " + std::to_string(level_count) +
                         " is not 1 to the image's " + std::to_string(image.mip_levels()) + " levels");
    }
    return level_count;
}

VkDeviceSize level_size(const Image& image, std::uint32_t level, const FormatBlock& block, const char* who) {
    const VkExtent3D e = image.extent(level);
    const VkDeviceSize columns = (VkDeviceSize(e.width) + block.width - 1) / block.width;
    const VkDeviceSize rows = (VkDeviceSize(e.height) + block.height - 1) / block.height;
    return checked_mul(checked_mul(checked_mul(columns, rows, who), e.depth, who), block.bytes, who);
}

void check_image_upload(const Image& image, Span<const std::byte> data, const ImageUploadInfo& info, const char* who) {
    checked_block(image, who);
    uploaded_levels(image, info.level_count, who);
    const VkDeviceSize expected = image_data_size(image, info.level_count);
    if (data.size() != expected) {
        throw UsageError(std::string(who) + ": " + std::to_string(data.size()) + " bytes given; " +
                         (info.level_count == VK_REMAINING_MIP_LEVELS ? std::string("every level")
                                                                      : std::to_string(info.level_count) + " levels") +
                         " and layer of the image take " + std::to_string(expected));
    }
    if (info.new_layout == VK_IMAGE_LAYOUT_UNDEFINED || info.new_layout == VK_IMAGE_LAYOUT_PREINITIALIZED) {
        throw UsageError(std::string(who) + ": new_layout must be a layout an image can be transitioned to");
    }
}

void check_image_download(const Image& image, VkImageLayout layout, std::uint32_t mip_level, std::uint32_t array_layer,
                          const char* who) {
    if (mip_level >= image.mip_levels() || array_layer >= image.array_layers()) {
        throw UsageError(std::string(who) + ": level " + std::to_string(mip_level) + " layer " +
                         std::to_string(array_layer) + " is not in the image");
    }
    if (layout == VK_IMAGE_LAYOUT_UNDEFINED) throw UsageError(std::string(who) + ": the image's layout is UNDEFINED");
    checked_block(image, who);
}

}  // namespace detail

VkDeviceSize image_data_size(const Image& image, std::uint32_t level_count) {
    constexpr const char* who = "vkrc::image_data_size";
    const FormatBlock block = detail::checked_block(image, who);
    const std::uint32_t levels = detail::uploaded_levels(image, level_count, who);
    VkDeviceSize total = 0;
    for (std::uint32_t level = 0; level < levels; ++level) {
        VkDeviceSize level_bytes;
        if (__builtin_mul_overflow(detail::level_size(image, level, block, who), image.array_layers(), &level_bytes) ||
            total + level_bytes < total)
            throw UsageError("vkrc::image_data_size: the image's size in bytes overflows 64 bits");
        total += level_bytes;
    }
    return total;
}

// The blocking path: an Uploader of the queue's own family, sized for the
// one transfer, and a wait for its ticket.
namespace {
Uploader one_time_uploader(const Queue& queue, VkDeviceSize size) {
    Uploader uploader =
        Uploader::create({.queue = queue, .consumer_family = queue.family_index(), .staging_size = size});
    uploader.state()->visible_at_end = true;
    return uploader;
}
}  // namespace

void upload_buffer(const Queue& queue, const Buffer& buffer, VkDeviceSize offset, Span<const std::byte> data) {
    constexpr const char* who = "vkrc::upload_buffer";
    detail::check_transfer(queue, buffer, VK_BUFFER_USAGE_TRANSFER_DST_BIT, "VK_BUFFER_USAGE_TRANSFER_DST_BIT", who);
    detail::check_buffer_range(buffer, offset, data.size(), who);
    if (data.empty()) return;
    Uploader uploader = one_time_uploader(queue, data.size());
    uploader.upload_buffer(buffer, offset, data);
    uploader.submit().wait_on_host();
}

List<std::byte> download_buffer(const Queue& queue, const Buffer& buffer, VkDeviceSize offset, VkDeviceSize size) {
    constexpr const char* who = "vkrc::download_buffer";
    detail::check_transfer(queue, buffer, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, "VK_BUFFER_USAGE_TRANSFER_SRC_BIT", who);
    detail::check_buffer_range(buffer, offset, size, who);
    if (size == 0) return {};
    Uploader uploader = one_time_uploader(queue, 1);
    Download download = uploader.download_buffer(buffer, offset, size);
    uploader.submit();
    return download.read();
}

void upload_image(const Queue& queue, const Image& image, Span<const std::byte> data, const ImageUploadInfo& info) {
    constexpr const char* who = "vkrc::upload_image";
    detail::check_transfer(queue, image, VK_IMAGE_USAGE_TRANSFER_DST_BIT, "VK_IMAGE_USAGE_TRANSFER_DST_BIT", who);
    detail::check_image_upload(image, data, info, who);
    Uploader uploader = one_time_uploader(queue, data.size());
    uploader.upload_image(image, data, info);
    uploader.submit().wait_on_host();
}

List<std::byte> download_image(const Queue& queue, const Image& image, VkImageLayout layout, std::uint32_t mip_level,
                               std::uint32_t array_layer) {
    constexpr const char* who = "vkrc::download_image";
    detail::check_transfer(queue, image, VK_IMAGE_USAGE_TRANSFER_SRC_BIT, "VK_IMAGE_USAGE_TRANSFER_SRC_BIT", who);
    detail::check_image_download(image, layout, mip_level, array_layer, who);
    Uploader uploader = one_time_uploader(queue, 1);
    Download download = uploader.download_image(image, layout, mip_level, array_layer);
    uploader.submit();
    return download.read();
}

VKRC_END_NAMESPACE
