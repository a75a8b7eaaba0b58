// Buffers, images, their views, and samplers.
#pragma once

#include "vkrc/memory.hpp"
#include "vkrc/ycbcr.hpp"

#include "vkrc/detail/list.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
class BufferState;
class ImageState;
class ImageViewState;
class BufferViewState;
class SamplerState;
}  // namespace detail

// Mirrors VkBufferCreateInfo, plus where its memory comes from.
struct BufferCreateInfo {
    // Optional (default none). Sparse flags are refused (UsageError): vkrc
    // binds one allocation to every buffer and has no sparse binding.
    VkBufferCreateFlags flags = 0;
    // Required, non-zero.
    VkDeviceSize size = 0;
    // Required, non-zero. SHADER_DEVICE_ADDRESS_BIT (needs the
    // bufferDeviceAddress feature) gets memory allocated with
    // DEVICE_ADDRESS_BIT and a device_address().
    VkBufferUsageFlags usage = 0;
    // Optional (default exclusive).
    VkSharingMode sharing_mode = VK_SHARING_MODE_EXCLUSIVE;
    // For concurrent sharing only. Read during create().
    List<std::uint32_t> queue_family_indices{};
    // Optional (default: GPU-only memory).
    MemoryIntent memory{};
    // Optional (null: the device's default PoolAllocator). Must outlive create();
    // the Device keeps it alive from then on.
    AllocatorView allocator{};
    // Optional pNext chain. Read during create(); need not outlive the call.
    const void* next = nullptr;
};

// A buffer bound to its own Allocation; keeps its Device and memory alive.
class Buffer : public DeviceChild<detail::BufferState, VkBuffer> {
public:
    static Buffer create(const Device& device, const BufferCreateInfo& info);
    // Wraps a buffer made elsewhere, its memory bound by its maker: the
    // result has no Allocation. With Ownership::owned vkrc destroys it.
    // cleanup, if given, runs once the GPU is done with the buffer (after
    // its destruction when owned), e.g. to free the memory its maker bound.
    static Buffer adopt(const Device& device, VkBuffer buffer, VkDeviceSize size, VkBufferUsageFlags usage,
                        Ownership ownership, Function<void()> cleanup = {});

    VkDeviceSize size() const VKRC_UNCHECKED_NOEXCEPT;
    VkBufferUsageFlags usage() const VKRC_UNCHECKED_NOEXCEPT;
    // The buffer's address for shaders (vkGetBufferDeviceAddress, read once
    // at creation); 0, never a valid address, without SHADER_DEVICE_ADDRESS usage.
    VkDeviceAddress device_address() const VKRC_UNCHECKED_NOEXCEPT;
    // Mapped access goes through the allocation: buffer.allocation().write(0, span).
    // Empty for an adopted buffer: its accessors then throw UsageError with
    // VKRC_RUNTIME_CHECKS (a precondition without).
    const Allocation& allocation() const VKRC_UNCHECKED_NOEXCEPT;

private:
    using DeviceChild::DeviceChild;
};

// Mirrors VkImageCreateInfo, plus where its memory comes from.
struct ImageCreateInfo {
    // Optional (default none). Sparse flags are refused by create() (UsageError), as for buffers.
    VkImageCreateFlags flags = 0;
    // Optional (default 2D).
    VkImageType image_type = VK_IMAGE_TYPE_2D;
    // Required.
    VkFormat format = VK_FORMAT_UNDEFINED;
    // Optional (default 1x1x1); no dimension may be 0.
    VkExtent3D extent{1, 1, 1};
    // Optional (default 1), non-zero.
    std::uint32_t mip_levels = 1;
    // Optional (default 1), non-zero.
    std::uint32_t array_layers = 1;
    // Optional (default one sample).
    VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT;
    // Optional (default optimal; linear asks the allocator for linear placement).
    VkImageTiling tiling = VK_IMAGE_TILING_OPTIMAL;
    // Required, non-zero.
    VkImageUsageFlags usage = 0;
    // Optional (default exclusive).
    VkSharingMode sharing_mode = VK_SHARING_MODE_EXCLUSIVE;
    // For concurrent sharing only. Read during create().
    List<std::uint32_t> queue_family_indices{};
    // Optional (default undefined).
    VkImageLayout initial_layout = VK_IMAGE_LAYOUT_UNDEFINED;
    // Optional (default: GPU-only memory). Ignored by adopt().
    MemoryIntent memory{};
    // Optional (null: the device's default allocator). Must outlive create();
    // the Device keeps it alive from then on. Ignored by adopt().
    AllocatorView allocator{};
    // Optional pNext chain. Read during create(); need not outlive the call.
    const void* next = nullptr;
};

// An image bound to its own Allocation; keeps its Device and memory alive.
class Image : public DeviceChild<detail::ImageState, VkImage> {
public:
    static Image create(const Device& device, const ImageCreateInfo& info);
    // Wraps an image made elsewhere (a swapchain's, with Ownership::borrowed);
    // info describes it (its memory and allocator fields are ignored). The
    // result has no Allocation. With Ownership::owned vkrc destroys it.
    // cleanup: as for Buffer::adopt.
    static Image adopt(const Device& device, VkImage image, const ImageCreateInfo& info, Ownership ownership,
                       Function<void()> cleanup = {});

    VkImageType image_type() const VKRC_UNCHECKED_NOEXCEPT;
    VkFormat format() const VKRC_UNCHECKED_NOEXCEPT;
    VkExtent3D extent() const VKRC_UNCHECKED_NOEXCEPT;
    // The extent of a mip level (each dimension halved per level, at least 1).
    VkExtent3D extent(std::uint32_t mip_level) const VKRC_UNCHECKED_NOEXCEPT;
    std::uint32_t mip_levels() const VKRC_UNCHECKED_NOEXCEPT;
    std::uint32_t array_layers() const VKRC_UNCHECKED_NOEXCEPT;
    VkSampleCountFlagBits samples() const VKRC_UNCHECKED_NOEXCEPT;
    VkImageUsageFlags usage() const VKRC_UNCHECKED_NOEXCEPT;
    const Allocation& allocation() const VKRC_UNCHECKED_NOEXCEPT;

private:
    using DeviceChild::DeviceChild;
};

// Mirrors VkImageViewCreateInfo (the image is the parent).
// Every member is optional.
struct ImageViewCreateInfo {
    // Default none.
    VkImageViewCreateFlags flags = 0;
    // Default 2D.
    VkImageViewType view_type = VK_IMAGE_VIEW_TYPE_2D;
    VkFormat format = VK_FORMAT_UNDEFINED;  // UNDEFINED: the image's format
    // Default identity.
    VkComponentMapping components{};
    // aspectMask 0: colour, or depth for depth formats (and stencil for depth-stencil ones).
    VkImageSubresourceRange subresource_range{0, 0, VK_REMAINING_MIP_LEVELS, 0, VK_REMAINING_ARRAY_LAYERS};
    // Default none. For views of Y'CbCr formats that a sampler with the same
    // conversion reads; vkrc chains VkSamplerYcbcrConversionInfo. The view keeps it alive.
    SamplerYcbcrConversion ycbcr_conversion{};
    // Optional pNext chain. Read during create(); need not outlive the call.
    const void* next = nullptr;
};

// Keeps its Image (and so the image's memory and Device) alive.
class ImageView : public VulkanObject<detail::ImageViewState, VkImageView> {
public:
    static ImageView create(const Image& image, const ImageViewCreateInfo& info = {});
    // Wraps a view of image made elsewhere, with the format and range it was
    // made with (aspectMask set). With Ownership::owned vkrc destroys it once
    // the GPU is done; borrowed, its maker does (after vkrc's last use).
    static ImageView adopt(const Image& image, VkImageView view, VkFormat format,
                           const VkImageSubresourceRange& subresource_range, Ownership ownership);

    const Image& image() const VKRC_UNCHECKED_NOEXCEPT;
    VkFormat format() const VKRC_UNCHECKED_NOEXCEPT;
    const VkImageSubresourceRange& subresource_range() const VKRC_UNCHECKED_NOEXCEPT;

private:
    using VulkanObject::VulkanObject;
};

// Mirrors VkBufferViewCreateInfo (the buffer is the parent).
struct BufferViewCreateInfo {
    // Optional (default none).
    VkBufferViewCreateFlags flags = 0;
    // Required.
    VkFormat format = VK_FORMAT_UNDEFINED;
    // Optional (default 0).
    VkDeviceSize offset = 0;
    // Optional (default: to the end of the buffer).
    VkDeviceSize range = VK_WHOLE_SIZE;
    // Optional pNext chain. Read during create(); need not outlive the call.
    const void* next = nullptr;
};

// Keeps its Buffer alive.
class BufferView : public VulkanObject<detail::BufferViewState, VkBufferView> {
public:
    static BufferView create(const Buffer& buffer, const BufferViewCreateInfo& info);
    // Wraps a view of buffer made elsewhere. With Ownership::owned vkrc
    // destroys it once the GPU is done; borrowed, its maker does.
    static BufferView adopt(const Buffer& buffer, VkBufferView view, Ownership ownership);

    const Buffer& buffer() const VKRC_UNCHECKED_NOEXCEPT;

private:
    using VulkanObject::VulkanObject;
};

// Mirrors VkSamplerCreateInfo.
// Every member is optional; the defaults (as initialised) give a trilinear, repeating sampler.
struct SamplerCreateInfo {
    VkSamplerCreateFlags flags = 0;
    VkFilter mag_filter = VK_FILTER_LINEAR;
    VkFilter min_filter = VK_FILTER_LINEAR;
    VkSamplerMipmapMode mipmap_mode = VK_SAMPLER_MIPMAP_MODE_LINEAR;
    VkSamplerAddressMode address_mode_u = VK_SAMPLER_ADDRESS_MODE_REPEAT;
    VkSamplerAddressMode address_mode_v = VK_SAMPLER_ADDRESS_MODE_REPEAT;
    VkSamplerAddressMode address_mode_w = VK_SAMPLER_ADDRESS_MODE_REPEAT;
    float mip_lod_bias = 0.0f;
    bool anisotropy_enable = false;
    float max_anisotropy = 1.0f;
    bool compare_enable = false;
    VkCompareOp compare_op = VK_COMPARE_OP_ALWAYS;
    float min_lod = 0.0f;
    float max_lod = VK_LOD_CLAMP_NONE;
    VkBorderColor border_color = VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK;
    bool unnormalized_coordinates = false;
    // Default none. vkrc chains VkSamplerYcbcrConversionInfo; the sampler keeps it alive.
    SamplerYcbcrConversion ycbcr_conversion{};
    // Optional pNext chain. Read during create(); need not outlive the call.
    const void* next = nullptr;
};

class Sampler : public DeviceChild<detail::SamplerState, VkSampler> {
public:
    static Sampler create(const Device& device, const SamplerCreateInfo& info = {});
    // Wraps one made elsewhere from the same device. With Ownership::owned vkrc
    // destroys it once the GPU is done; borrowed, its maker does (after vkrc's last use).
    static Sampler adopt(const Device& device, VkSampler sampler, Ownership ownership);

private:
    using DeviceChild::DeviceChild;
};

// The aspects of a format: depth and/or stencil, or colour.
VkImageAspectFlags format_aspects(VkFormat format) noexcept;

// Bytes per texel of an uncompressed colour format; 0 for formats the
// staging functions (vkrc/upload.hpp) do not handle (compressed,
// depth/stencil, planar).
std::uint32_t format_texel_size(VkFormat format) noexcept;

// The unit a format's data is copied in: a texel (1 x 1) of an uncompressed
// colour format, or a block of a block-compressed one (BC, ETC2/EAC, ASTC
// LDR). bytes is 0 for formats the staging functions do not handle.
struct FormatBlock {
    std::uint32_t bytes = 0;
    std::uint32_t width = 1;
    std::uint32_t height = 1;
};
FormatBlock format_block(VkFormat format) noexcept;

namespace detail {

// Queues cleanup to run once the GPU is done with what was dropped before it.
void defer_cleanup(DeviceState& device, Function<void()>& cleanup, std::uint64_t serial) noexcept;

class BufferState final : public DeviceChildState<VkBuffer> {
public:
    static constexpr const char* type_name = "vkrc::Buffer";
    ~BufferState() override;
    VkDeviceSize size = 0;
    VkBufferUsageFlags usage = 0;
    VkDeviceAddress device_address = 0;
    Allocation allocation;       // released after the buffer's destruction is queued
    Function<void()> cleanup{};  // an adopted buffer's, queued after its destruction
};

class ImageState final : public DeviceChildState<VkImage> {
public:
    static constexpr const char* type_name = "vkrc::Image";
    ~ImageState() override;
    VkImageType image_type = VK_IMAGE_TYPE_2D;
    VkFormat format = VK_FORMAT_UNDEFINED;
    VkExtent3D extent{};
    std::uint32_t mip_levels = 1;
    std::uint32_t array_layers = 1;
    VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT;
    VkImageUsageFlags usage = 0;
    VkImageCreateFlags flags = 0;
    VkImageTiling tiling = VK_IMAGE_TILING_OPTIMAL;
    Allocation allocation;
    Function<void()> cleanup{};  // an adopted image's, queued after its destruction
    // What a borrowed image belongs to and keeps alive (a swapchain's images
    // keep their swapchain); released first, after the image's own teardown.
    Ref<RefCounted> owner;
};

class ImageViewState final : public VulkanObjectState<VkImageView> {
public:
    static constexpr const char* type_name = "vkrc::ImageView";
    ~ImageViewState() override;
    Image image;
    VkFormat format = VK_FORMAT_UNDEFINED;
    VkImageSubresourceRange range{};
    SamplerYcbcrConversion ycbcr_conversion;  // if made with one
};

class BufferViewState final : public VulkanObjectState<VkBufferView> {
public:
    static constexpr const char* type_name = "vkrc::BufferView";
    ~BufferViewState() override;
    Buffer buffer;
};

class SamplerState final : public DeviceChildState<VkSampler> {
public:
    static constexpr const char* type_name = "vkrc::Sampler";
    ~SamplerState() override;
    SamplerYcbcrConversion ycbcr_conversion;  // if made with one
};

}  // namespace detail

inline VkDeviceSize Buffer::size() const VKRC_UNCHECKED_NOEXCEPT { return live("vkrc::Buffer::size").size; }
inline VkBufferUsageFlags Buffer::usage() const VKRC_UNCHECKED_NOEXCEPT { return live("vkrc::Buffer::usage").usage; }
inline VkDeviceAddress Buffer::device_address() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::Buffer::device_address").device_address;
}
inline const Allocation& Buffer::allocation() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::Buffer::allocation").allocation;
}

inline VkImageType Image::image_type() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::Image::image_type").image_type;
}
inline VkFormat Image::format() const VKRC_UNCHECKED_NOEXCEPT { return live("vkrc::Image::format").format; }
inline VkExtent3D Image::extent() const VKRC_UNCHECKED_NOEXCEPT { return live("vkrc::Image::extent").extent; }
inline VkExtent3D Image::extent(std::uint32_t level) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::Image::extent");
    auto e = state_->extent;
    auto half = [level](std::uint32_t v) { return v >> level ? v >> level : 1u; };
    return {half(e.width), half(e.height), half(e.depth)};
}
inline std::uint32_t Image::mip_levels() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::Image::mip_levels").mip_levels;
}
inline std::uint32_t Image::array_layers() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::Image::array_layers").array_layers;
}
inline VkSampleCountFlagBits Image::samples() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::Image::samples").samples;
}
inline VkImageUsageFlags Image::usage() const VKRC_UNCHECKED_NOEXCEPT { return live("vkrc::Image::usage").usage; }
inline const Allocation& Image::allocation() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::Image::allocation").allocation;
}

inline const Image& ImageView::image() const VKRC_UNCHECKED_NOEXCEPT { return live("vkrc::ImageView::image").image; }
inline VkFormat ImageView::format() const VKRC_UNCHECKED_NOEXCEPT { return live("vkrc::ImageView::format").format; }
inline const VkImageSubresourceRange& ImageView::subresource_range() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::ImageView::subresource_range").range;
}

inline const Buffer& BufferView::buffer() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::BufferView::buffer").buffer;
}

VKRC_END_NAMESPACE
