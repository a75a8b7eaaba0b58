#include "vkrc/upload.hpp"

#include "vkrc/submit.hpp"
#include "vkrc/sync.hpp"

#include "enum_names.hpp"

#include <string>
#include <type_traits>
#include <vector>

VKRC_BEGIN_NAMESPACE

std::uint32_t format_texel_size(VkFormat format) noexcept {
    const int f = static_cast<int>(format);
    if (f == VK_FORMAT_R4G4_UNORM_PACK8) return 1;
    if (f >= VK_FORMAT_R4G4B4A4_UNORM_PACK16 && f <= VK_FORMAT_A1R5G5B5_UNORM_PACK16) return 2;
    if (f >= VK_FORMAT_R8_UNORM && f <= VK_FORMAT_R8_SRGB) return 1;
    if (f >= VK_FORMAT_R8G8_UNORM && f <= VK_FORMAT_R8G8_SRGB) return 2;
    if (f >= VK_FORMAT_R8G8B8_UNORM && f <= VK_FORMAT_B8G8R8_SRGB) return 3;
    if (f >= VK_FORMAT_R8G8B8A8_UNORM && f <= VK_FORMAT_A2B10G10R10_SINT_PACK32) return 4;
    if (f >= VK_FORMAT_R16_UNORM && f <= VK_FORMAT_R16_SFLOAT) return 2;
    if (f >= VK_FORMAT_R16G16_UNORM && f <= VK_FORMAT_R16G16_SFLOAT) return 4;
    if (f >= VK_FORMAT_R16G16B16_UNORM && f <= VK_FORMAT_R16G16B16_SFLOAT) return 6;
    if (f >= VK_FORMAT_R16G16B16A16_UNORM && f <= VK_FORMAT_R16G16B16A16_SFLOAT) return 8;
    if (f >= VK_FORMAT_R32_UINT && f <= VK_FORMAT_R32_SFLOAT) return 4;
    if (f >= VK_FORMAT_R32G32_UINT && f <= VK_FORMAT_R32G32_SFLOAT) return 8;
    if (f >= VK_FORMAT_R32G32B32_UINT && f <= VK_FORMAT_R32G32B32_SFLOAT) return 12;
    if (f >= VK_FORMAT_R32G32B32A32_UINT && f <= VK_FORMAT_R32G32B32A32_SFLOAT) return 16;
    if (f >= VK_FORMAT_R64_UINT && f <= VK_FORMAT_R64_SFLOAT) return 8;
    if (f >= VK_FORMAT_R64G64_UINT && f <= VK_FORMAT_R64G64_SFLOAT) return 16;
    if (f >= VK_FORMAT_R64G64B64_UINT && f <= VK_FORMAT_R64G64B64_SFLOAT) return 24;
    if (f >= VK_FORMAT_R64G64B64A64_UINT && f <= VK_FORMAT_R64G64B64A64_SFLOAT) return 32;
    if (f == VK_FORMAT_B10G11R11_UFLOAT_PACK32 || f == VK_FORMAT_E5B9G9R9_UFLOAT_PACK32) return 4;
    return 0;
}

namespace {

// One command buffer from a transient pool, submitted and waited for. The
// pool, command buffer and fence are vkrc objects, so their destruction is
// deferred past the submitted work like any other (a failed wait included).
class OneTimeCommands {
public:
    explicit OneTimeCommands(const Queue& queue)
        : queue_(queue),
          pool_(CommandPool::create(queue.device(), {VK_COMMAND_POOL_CREATE_TRANSIENT_BIT, queue.family_index()})),
          cmd_(pool_.allocate()) {
        cmd_.begin(VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT);
    }

    VkCommandBuffer cmd() const noexcept { return cmd_.vk(); }
    const DeviceFunctions& fn() const noexcept { return cmd_.fn(); }

    void submit_and_wait() {
        cmd_.end();
        Fence fence = Fence::create(queue_.device());
        submit(queue_, SubmitBatch{{}, {&cmd_, 1}, {}}, fence);
        fence.wait();
    }

    void image_barrier(VkImage image, VkImageLayout old_layout, VkImageLayout new_layout,
                       VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access, VkPipelineStageFlags2 dst_stage,
                       VkAccessFlags2 dst_access, const VkImageSubresourceRange& range) const {
        VkImageMemoryBarrier2 b = vkrc::image_barrier(image, old_layout, new_layout, src_stage, src_access, dst_stage,
                                                      dst_access, range.aspectMask);
        b.subresourceRange = range;
        cmd_.pipeline_barrier({}, {}, {&b, 1});
    }
    void memory_barrier(VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access, VkPipelineStageFlags2 dst_stage,
                        VkAccessFlags2 dst_access) const {
        const VkMemoryBarrier2 b = vkrc::memory_barrier(src_stage, src_access, dst_stage, dst_access);
        cmd_.pipeline_barrier({&b, 1}, {}, {});
    }

private:
    Queue queue_;
    CommandPool pool_;
    CommandBuffer cmd_;
};

Buffer staging_buffer(const Device& device, VkDeviceSize size, MemoryUsage usage) {
    BufferCreateInfo info;
    info.size = size;
    info.usage = usage == MemoryUsage::upload ? VK_BUFFER_USAGE_TRANSFER_SRC_BIT : VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    info.memory.usage = usage;
    return Buffer::create(device, info);
}

// The checks every transfer starts with: the buffer or image exists, belongs
// to the queue's device and has the transfer usage (usage_name) it needs.
template <class Resource>
void check_transfer(const Queue& queue, const Resource& resource, std::uint32_t usage, const char* usage_name,
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

std::uint32_t checked_texel_size(const Image& image, const char* who) {
    const std::uint32_t texel = format_texel_size(image.format());
    if (texel == 0) {
        throw UsageError(std::string(who) + ": format " + detail::enum_text(image.format()) +
                         " is not an uncompressed colour format");
    }
    if (image.samples() != VK_SAMPLE_COUNT_1_BIT) throw UsageError(std::string(who) + ": the image is multisampled");
    return texel;
}

// a * b, or UsageError naming who when it does not fit in 64 bits.
VkDeviceSize checked_mul(VkDeviceSize a, VkDeviceSize b, const char* who) {
    VkDeviceSize r;
    if (__builtin_mul_overflow(a, b, &r)) {
        throw UsageError(std::string(who) + ": the image's size in bytes overflows 64 bits");
    }
    return r;
}

VkDeviceSize level_size(const Image& image, std::uint32_t level, std::uint32_t texel, const char* who) {
    const VkExtent3D e = image.extent(level);
    return checked_mul(checked_mul(checked_mul(e.width, e.height, who), e.depth, who), texel, who);
}

}  // namespace

void upload_buffer(const Queue& queue, const Buffer& buffer, VkDeviceSize offset, std::span<const std::byte> data) {
    constexpr const char* who = "vkrc::upload_buffer";
    check_transfer(queue, buffer, VK_BUFFER_USAGE_TRANSFER_DST_BIT, "VK_BUFFER_USAGE_TRANSFER_DST_BIT", who);
    if (offset > buffer.size() || data.size() > buffer.size() - offset) {
        throw UsageError(std::string(who) + ": " + std::to_string(data.size()) + " bytes at offset " +
                         std::to_string(offset) + " do not fit in the " + std::to_string(buffer.size()) +
                         "-byte buffer");
    }
    if (data.empty()) return;
    Buffer staging = staging_buffer(buffer.device(), data.size(), MemoryUsage::upload);
    staging.allocation().write(0, data);
    OneTimeCommands commands(queue);
    // Earlier submissions' reads and writes of the buffer end before the copy
    // writes it (as in upload_image).
    commands.memory_barrier(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                            VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    VkBufferCopy region{0, offset, data.size()};
    commands.fn().vkCmdCopyBuffer(commands.cmd(), staging.vk(), buffer.vk(), 1, &region);
    // Later submissions see the copy (their commands are in the second scope).
    commands.memory_barrier(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                            VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                            VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT);
    commands.submit_and_wait();
}

List<std::byte> download_buffer(const Queue& queue, const Buffer& buffer, VkDeviceSize offset, VkDeviceSize size) {
    constexpr const char* who = "vkrc::download_buffer";
    check_transfer(queue, buffer, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, "VK_BUFFER_USAGE_TRANSFER_SRC_BIT", who);
    if (offset > buffer.size() || size > buffer.size() - offset) {
        throw UsageError(std::string(who) + ": " + std::to_string(size) + " bytes at offset " + std::to_string(offset) +
                         " are not all in the " + std::to_string(buffer.size()) + "-byte buffer");
    }
    std::vector<std::byte> out(size);
    if (size == 0) return out;
    Buffer readback = staging_buffer(buffer.device(), size, MemoryUsage::readback);
    OneTimeCommands commands(queue);
    // Earlier submissions' writes to the buffer are made visible to the copy.
    commands.memory_barrier(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                            VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    VkBufferCopy region{offset, 0, size};
    commands.fn().vkCmdCopyBuffer(commands.cmd(), buffer.vk(), readback.vk(), 1, &region);
    commands.memory_barrier(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                            VK_ACCESS_2_HOST_READ_BIT);
    commands.submit_and_wait();
    readback.allocation().read(0, std::span<std::byte>(out));
    return out;
}

VkDeviceSize image_data_size(const Image& image) {
    const std::uint32_t texel = checked_texel_size(image, "vkrc::image_data_size");
    VkDeviceSize total = 0;
    for (std::uint32_t level = 0; level < image.mip_levels(); ++level) {
        const VkDeviceSize level_bytes = checked_mul(level_size(image, level, texel, "vkrc::image_data_size"),
                                                     image.array_layers(), "vkrc::image_data_size");
        if (total + level_bytes < total)
            throw UsageError("vkrc::image_data_size: the image's size in bytes overflows 64 bits");
        total += level_bytes;
    }
    return total;
}

void upload_image(const Queue& queue, const Image& image, std::span<const std::byte> data,
                  const ImageUploadInfo& info) {
    constexpr const char* who = "vkrc::upload_image";
    check_transfer(queue, image, VK_IMAGE_USAGE_TRANSFER_DST_BIT, "VK_IMAGE_USAGE_TRANSFER_DST_BIT", who);
    const std::uint32_t texel = checked_texel_size(image, who);
    const VkDeviceSize expected = image_data_size(image);
    if (data.size() != expected) {
        throw UsageError(std::string(who) + ": " + std::to_string(data.size()) +
                         " bytes given; every level and layer of " + "the image takes " + std::to_string(expected));
    }
    if (info.new_layout == VK_IMAGE_LAYOUT_UNDEFINED || info.new_layout == VK_IMAGE_LAYOUT_PREINITIALIZED) {
        throw UsageError(std::string(who) + ": new_layout must be a layout an image can be transitioned to");
    }
    Buffer staging = staging_buffer(image.device(), expected, MemoryUsage::upload);
    staging.allocation().write(0, data);

    std::vector<VkBufferImageCopy> regions;
    regions.reserve(image.mip_levels());
    VkDeviceSize offset = 0;
    for (std::uint32_t level = 0; level < image.mip_levels(); ++level) {
        VkBufferImageCopy r{};
        r.bufferOffset = offset;
        r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, level, 0, image.array_layers()};
        r.imageExtent = image.extent(level);
        regions.push_back(r);
        offset += level_size(image, level, texel, who) * image.array_layers();
    }
    const VkImageSubresourceRange all{VK_IMAGE_ASPECT_COLOR_BIT, 0, image.mip_levels(), 0, image.array_layers()};
    OneTimeCommands commands(queue);
    // From whatever earlier work did with the image to the copy.
    commands.image_barrier(image.vk(), info.old_layout, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                           VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                           VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, all);
    commands.fn().vkCmdCopyBufferToImage(commands.cmd(), staging.vk(), image.vk(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                         static_cast<std::uint32_t>(regions.size()), regions.data());
    // From the copy to whatever later work does with the image.
    commands.image_barrier(image.vk(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, info.new_layout,
                           VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                           VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                           VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT, all);
    commands.submit_and_wait();
}

List<std::byte> download_image(const Queue& queue, const Image& image, VkImageLayout layout, std::uint32_t mip_level,
                               std::uint32_t array_layer) {
    constexpr const char* who = "vkrc::download_image";
    check_transfer(queue, image, VK_IMAGE_USAGE_TRANSFER_SRC_BIT, "VK_IMAGE_USAGE_TRANSFER_SRC_BIT", who);
    if (mip_level >= image.mip_levels() || array_layer >= image.array_layers()) {
        throw UsageError(std::string(who) + ": level " + std::to_string(mip_level) + " layer " +
                         std::to_string(array_layer) + " is not in the image");
    }
    if (layout == VK_IMAGE_LAYOUT_UNDEFINED) throw UsageError(std::string(who) + ": the image's layout is UNDEFINED");
    const std::uint32_t texel = checked_texel_size(image, who);
    const VkDeviceSize size = level_size(image, mip_level, texel, who);
    Buffer readback = staging_buffer(image.device(), size, MemoryUsage::readback);
    const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, mip_level, 1, array_layer, 1};
    OneTimeCommands commands(queue);
    commands.image_barrier(image.vk(), layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                           VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT, range);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, mip_level, array_layer, 1};
    region.imageExtent = image.extent(mip_level);
    commands.fn().vkCmdCopyImageToBuffer(commands.cmd(), image.vk(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                         readback.vk(), 1, &region);
    commands.image_barrier(image.vk(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, layout, VK_PIPELINE_STAGE_2_COPY_BIT,
                           VK_ACCESS_2_NONE, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                           VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT, range);
    commands.memory_barrier(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                            VK_ACCESS_2_HOST_READ_BIT);
    commands.submit_and_wait();
    std::vector<std::byte> out(size);
    readback.allocation().read(0, std::span<std::byte>(out));
    return out;
}

VKRC_END_NAMESPACE
