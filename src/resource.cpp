#include "vkrc/resource.hpp"

#include "object_state.hpp"
#include "enum_names.hpp"

#include <algorithm>
#include <string>
#include <type_traits>

VKRC_BEGIN_NAMESPACE

namespace detail {

// Each state queues its handle's destruction in its destructor body; its
// members (the allocation, then the parents) are released after, so FIFO
// order destroys the handle before its memory returns and before its parent.
BufferState::~BufferState() {
    if (device) device.state()->objects.remove(DescribedKind::buffer, handle_bits(handle), this);
    destroy_owned<&DeviceFunctions::vkDestroyBuffer>(*this, device);
    if (device && cleanup) defer_cleanup(*device.state(), cleanup, serial());
}
ImageState::~ImageState() {
    destroy_owned<&DeviceFunctions::vkDestroyImage>(*this, device);
    if (device && cleanup) defer_cleanup(*device.state(), cleanup, serial());
}

void defer_cleanup(DeviceState& device, Function<void()>& cleanup, std::uint64_t serial) noexcept {
    auto run = [](DeviceState&, std::uint64_t, void* context) noexcept {
        auto* f = static_cast<Function<void()>*>(context);
        try {
            (*f)();
        } catch (...) {
            // A destructor path has no one to report to; the callback's failure is its own.
        }
        delete f;
    };
    Function<void()>* held = nullptr;
    try {
        held = new Function<void()>(std::move(cleanup));
    } catch (...) {
        // Out of host memory: waiting is the only safe way left to run it now.
        device.fn.vkDeviceWaitIdle(device.device);
        try {
            cleanup();
        } catch (...) {}
        return;
    }
    device.destroy_after_gpu({run, 0, held}, serial);
}
ImageViewState::~ImageViewState() {
    if (!image) return;
    image.device().state()->objects.remove(DescribedKind::image_view, handle_bits(handle), this);
    destroy_owned<&DeviceFunctions::vkDestroyImageView>(*this, image.device());
}
BufferViewState::~BufferViewState() {
    if (!buffer) return;
    buffer.device().state()->objects.remove(DescribedKind::buffer_view, handle_bits(handle), this);
    destroy_owned<&DeviceFunctions::vkDestroyBufferView>(*this, buffer.device());
}
SamplerState::~SamplerState() {
    if (device) device.state()->objects.remove(DescribedKind::sampler, handle_bits(handle), this);
    destroy_owned<&DeviceFunctions::vkDestroySampler>(*this, device);
}

// Makes state findable by its raw handle (descriptor writes of raw handles
// keep it alive through it); its destructor above forgets it.
// An adoption that fails here leaves the handle to its caller (as every
// failed adopt does), so the state gives it up before it goes.
template <class State>
Ref<State> registered(Ref<State> state, const Device& device, DescribedKind kind, bool adopted = false) {
    try {
        device.state()->objects.add(kind, handle_bits(state->handle), state.get());
    } catch (...) {
        if (adopted) state->ownership = Ownership::borrowed;
        throw;
    }
    return state;
}

}  // namespace detail

namespace {

// Buffer::create and Image::create once the info is checked: vkCreate* into
// the state (which owns the handle from then on, so a failure below destroys
// it), memory for its requirements (with the dedicated ones) from the
// allocator, and the bind. request carries the intent and placement.
template <class State, class CreateInfo>
void create_bound(const Device& device, const CreateInfo& ci, State& state, AllocationRequest request,
                  const SharedAllocator& allocator) {
    constexpr bool is_buffer = std::is_same_v<State, detail::BufferState>;
    const auto& fn = device.fn();
    VkMemoryDedicatedRequirements dedicated{VK_STRUCTURE_TYPE_MEMORY_DEDICATED_REQUIREMENTS};
    VkMemoryRequirements2 requirements{VK_STRUCTURE_TYPE_MEMORY_REQUIREMENTS_2, &dedicated};
    if constexpr (is_buffer) {
        check(fn.vkCreateBuffer(device.vk(), &ci, nullptr, &state.handle), "vkCreateBuffer");
        request.dedicated_buffer = state.handle;
        const VkBufferMemoryRequirementsInfo2 query{VK_STRUCTURE_TYPE_BUFFER_MEMORY_REQUIREMENTS_INFO_2, nullptr,
                                                    state.handle};
        fn.vkGetBufferMemoryRequirements2(device.vk(), &query, &requirements);
    } else {
        check(fn.vkCreateImage(device.vk(), &ci, nullptr, &state.handle), "vkCreateImage");
        request.dedicated_image = state.handle;
        const VkImageMemoryRequirementsInfo2 query{VK_STRUCTURE_TYPE_IMAGE_MEMORY_REQUIREMENTS_INFO_2, nullptr,
                                                   state.handle};
        fn.vkGetImageMemoryRequirements2(device.vk(), &query, &requirements);
    }
    request.requirements = requirements.memoryRequirements;
    request.prefers_dedicated = dedicated.prefersDedicatedAllocation;
    request.requires_dedicated = dedicated.requiresDedicatedAllocation;
    state.allocation = Allocation::create(device, request, allocator);
    const VkDeviceMemory memory = state.allocation.memory();
    const VkDeviceSize offset = state.allocation.offset();
    if constexpr (is_buffer) {
        check(fn.vkBindBufferMemory(device.vk(), state.handle, memory, offset), "vkBindBufferMemory");
    } else {
        check(fn.vkBindImageMemory(device.vk(), state.handle, memory, offset), "vkBindImageMemory");
    }
}

// The sharing of a VkBufferCreateInfo or VkImageCreateInfo from vkrc's info
// (the queue families matter for concurrent sharing only).
template <class CreateInfo, class Info>
void set_sharing(CreateInfo& ci, const Info& info) noexcept {
    ci.sharingMode = info.sharing_mode;
    ci.queueFamilyIndexCount = static_cast<std::uint32_t>(info.queue_family_indices.size());
    ci.pQueueFamilyIndices = info.queue_family_indices.data();
}

// The address of a bound buffer with SHADER_DEVICE_ADDRESS usage; 0 without.
VkDeviceAddress query_device_address(const Device& device, VkBuffer buffer, VkBufferUsageFlags usage) {
    if (!(usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT)) return 0;
    const VkBufferDeviceAddressInfo query{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO, nullptr, buffer};
    return device.fn().vkGetBufferDeviceAddress(device.vk(), &query);
}

// VkSamplerYcbcrConversionInfo for conversion (if any) ahead of next; the
// conversion must belong to device.
VkSamplerYcbcrConversionInfo conversion_info(const Device& device, const SamplerYcbcrConversion& conversion,
                                             const void* next, const char* who) {
    VkSamplerYcbcrConversionInfo info{VK_STRUCTURE_TYPE_SAMPLER_YCBCR_CONVERSION_INFO, next};
    if (!conversion) return info;
    if (!(conversion.device() == device)) {
        throw UsageError(std::string(who) + ": the SamplerYcbcrConversion belongs to another device");
    }
    info.conversion = conversion.vk();
    return info;
}

// The state of a buffer, created or adopted (the handle is set by the caller).
detail::Ref<detail::BufferState> buffer_state(const Device& device, VkDeviceSize size, VkBufferUsageFlags usage,
                                              Ownership ownership) {
    detail::Ref<detail::BufferState> state(new detail::BufferState);
    state->device = device;
    state->size = size;
    state->usage = usage;
    state->ownership = ownership;
    return state;
}

// The state of an image as info describes it, created or adopted.
detail::Ref<detail::ImageState> image_state(const Device& device, const ImageCreateInfo& info, Ownership ownership) {
    detail::Ref<detail::ImageState> state(new detail::ImageState);
    state->device = device;
    state->image_type = info.image_type;
    state->format = info.format;
    state->extent = info.extent;
    state->mip_levels = info.mip_levels;
    state->array_layers = info.array_layers;
    state->samples = info.samples;
    state->usage = info.usage;
    state->flags = info.flags;
    state->ownership = ownership;
    return state;
}

}  // namespace

Buffer Buffer::create(const Device& device, const BufferCreateInfo& info) {
    detail::require_handle(device, "vkrc::Buffer::create", "the Device");
    if (info.size == 0) throw UsageError("vkrc::Buffer::create: size is 0");
    if (info.usage == 0) throw UsageError("vkrc::Buffer::create: usage is 0");
    constexpr VkBufferCreateFlags sparse = VK_BUFFER_CREATE_SPARSE_BINDING_BIT | VK_BUFFER_CREATE_SPARSE_RESIDENCY_BIT |
                                           VK_BUFFER_CREATE_SPARSE_ALIASED_BIT;
    if (info.flags & sparse) {
        throw UsageError(
            "vkrc::Buffer::create: sparse flags are not supported (vkrc binds one allocation to each buffer; create "
            "a sparse buffer with vkCreateBuffer and bind it with vkQueueBindSparse)");
    }
    {
        // A size no heap can hold (a negative number cast to VkDeviceSize, a
        // product that wrapped) fails here with its value, not later with
        // an out-of-memory from the allocator's alignment arithmetic.
        const auto& memory = device.physical_device().memory_properties();
        VkDeviceSize largest = 0;
        for (std::uint32_t i = 0; i < memory.memoryHeapCount; ++i)
            largest = std::max(largest, memory.memoryHeaps[i].size);
        if (info.size > largest) {
            throw UsageError("vkrc::Buffer::create: size " + std::to_string(info.size) +
                             " is larger than every memory heap of the device (the largest has " +
                             std::to_string(largest) + " bytes)");
        }
    }
    VkBufferCreateInfo ci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, info.next};
    ci.flags = info.flags;
    ci.size = info.size;
    ci.usage = info.usage;
    set_sharing(ci, info);
    AllocationRequest request;
    request.intent = info.memory;
    request.linear = true;
    request.device_address = (info.usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) != 0;
    auto state = buffer_state(device, info.size, info.usage, Ownership::owned);
    create_bound(device, ci, *state, request, info.allocator);
    state->device_address = query_device_address(device, state->handle, info.usage);
    return Buffer(detail::registered(std::move(state), device, detail::DescribedKind::buffer));
}

Buffer Buffer::adopt(const Device& device, VkBuffer buffer, VkDeviceSize size, VkBufferUsageFlags usage,
                     Ownership ownership, Function<void()> cleanup) {
    detail::require_handle(device, "vkrc::Buffer::adopt", "the Device");
    if (buffer == VK_NULL_HANDLE) throw UsageError("vkrc::Buffer::adopt: the VkBuffer is VK_NULL_HANDLE");
    auto state = buffer_state(device, size, usage, ownership);
    state->handle = buffer;
    state->cleanup = std::move(cleanup);
    state->device_address = query_device_address(device, buffer, usage);
    return Buffer(detail::registered(std::move(state), device, detail::DescribedKind::buffer, true));
}

VkImageAspectFlags format_aspects(VkFormat format) noexcept {
    switch (format) {
        case VK_FORMAT_D16_UNORM:
        case VK_FORMAT_X8_D24_UNORM_PACK32:
        case VK_FORMAT_D32_SFLOAT: return VK_IMAGE_ASPECT_DEPTH_BIT;
        case VK_FORMAT_S8_UINT: return VK_IMAGE_ASPECT_STENCIL_BIT;
        case VK_FORMAT_D16_UNORM_S8_UINT:
        case VK_FORMAT_D24_UNORM_S8_UINT:
        case VK_FORMAT_D32_SFLOAT_S8_UINT: return VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT;
        default: return VK_IMAGE_ASPECT_COLOR_BIT;
    }
}

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

FormatBlock format_block(VkFormat format) noexcept {
    const int f = static_cast<int>(format);
    if (const std::uint32_t texel = format_texel_size(format)) return {texel, 1, 1};
    // BC1 and BC4 take 8 bytes per 4x4 block, BC2, 3, 5, 6H and 7 take 16.
    if (f >= VK_FORMAT_BC1_RGB_UNORM_BLOCK && f <= VK_FORMAT_BC7_SRGB_BLOCK) {
        const bool half =
            f <= VK_FORMAT_BC1_RGBA_SRGB_BLOCK || (f >= VK_FORMAT_BC4_UNORM_BLOCK && f <= VK_FORMAT_BC4_SNORM_BLOCK);
        return {half ? 8u : 16u, 4, 4};
    }
    // ETC2 RGB8, RGB8A1 and EAC R11 take 8 bytes per 4x4 block; ETC2 RGBA8 and EAC RG11 take 16.
    if (f >= VK_FORMAT_ETC2_R8G8B8_UNORM_BLOCK && f <= VK_FORMAT_EAC_R11G11_SNORM_BLOCK) {
        const bool half = f <= VK_FORMAT_ETC2_R8G8B8A1_SRGB_BLOCK ||
                          (f >= VK_FORMAT_EAC_R11_UNORM_BLOCK && f <= VK_FORMAT_EAC_R11_SNORM_BLOCK);
        return {half ? 8u : 16u, 4, 4};
    }
    // ASTC LDR: 16 bytes per block, the extents in enum order (UNORM, SRGB pairs).
    if (f >= VK_FORMAT_ASTC_4x4_UNORM_BLOCK && f <= VK_FORMAT_ASTC_12x12_SRGB_BLOCK) {
        static constexpr std::uint8_t extents[14][2] = {{4, 4},  {5, 4},   {5, 5},   {6, 5},  {6, 6},
                                                        {8, 5},  {8, 6},   {8, 8},   {10, 5}, {10, 6},
                                                        {10, 8}, {10, 10}, {12, 10}, {12, 12}};
        const auto& e = extents[(f - VK_FORMAT_ASTC_4x4_UNORM_BLOCK) / 2];
        return {16, e[0], e[1]};
    }
    return {};
}

Image Image::create(const Device& device, const ImageCreateInfo& info) {
    detail::require_handle(device, "vkrc::Image::create", "the Device");
    if (info.format == VK_FORMAT_UNDEFINED) throw UsageError("vkrc::Image::create: format is VK_FORMAT_UNDEFINED");
    if (info.extent.width == 0 || info.extent.height == 0 || info.extent.depth == 0) {
        throw UsageError("vkrc::Image::create: extent has a zero dimension");
    }
    if (info.mip_levels == 0 || info.array_layers == 0) {
        throw UsageError("vkrc::Image::create: mip_levels and array_layers must be at least 1");
    }
    if (info.usage == 0) throw UsageError("vkrc::Image::create: usage is 0");
    constexpr VkImageCreateFlags sparse =
        VK_IMAGE_CREATE_SPARSE_BINDING_BIT | VK_IMAGE_CREATE_SPARSE_RESIDENCY_BIT | VK_IMAGE_CREATE_SPARSE_ALIASED_BIT;
    if (info.flags & sparse) {
        throw UsageError(
            "vkrc::Image::create: sparse flags are not supported (vkrc binds one allocation to each image; create a "
            "sparse image with vkCreateImage and bind it with vkQueueBindSparse)");
    }
    VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO, info.next};
    ci.flags = info.flags;
    ci.imageType = info.image_type;
    ci.format = info.format;
    ci.extent = info.extent;
    ci.mipLevels = info.mip_levels;
    ci.arrayLayers = info.array_layers;
    ci.samples = info.samples;
    ci.tiling = info.tiling;
    ci.usage = info.usage;
    set_sharing(ci, info);
    ci.initialLayout = info.initial_layout;
    AllocationRequest request;
    request.intent = info.memory;
    request.linear = info.tiling == VK_IMAGE_TILING_LINEAR;
    auto state = image_state(device, info, Ownership::owned);
    create_bound(device, ci, *state, request, info.allocator);
    return Image(std::move(state));
}

Image Image::adopt(const Device& device, VkImage image, const ImageCreateInfo& info, Ownership ownership,
                   Function<void()> cleanup) {
    detail::require_handle(device, "vkrc::Image::adopt", "the Device");
    if (image == VK_NULL_HANDLE) throw UsageError("vkrc::Image::adopt: the VkImage is VK_NULL_HANDLE");
    auto state = image_state(device, info, ownership);
    state->handle = image;
    state->cleanup = std::move(cleanup);
    return Image(std::move(state));
}

ImageView ImageView::create(const Image& image, const ImageViewCreateInfo& info) {
    detail::require_handle(image, "vkrc::ImageView::create", "the Image");
    VkSamplerYcbcrConversionInfo conversion =
        conversion_info(image.device(), info.ycbcr_conversion, info.next, "vkrc::ImageView::create");
    VkImageViewCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO, info.ycbcr_conversion ? &conversion : info.next};
    ci.flags = info.flags;
    ci.image = image.vk();
    ci.viewType = info.view_type;
    ci.format = info.format == VK_FORMAT_UNDEFINED ? image.format() : info.format;
    ci.components = info.components;
    ci.subresourceRange = info.subresource_range;
    if (ci.subresourceRange.aspectMask == 0) ci.subresourceRange.aspectMask = format_aspects(ci.format);
    // Free checks (create is a cold path): the range within the image, the
    // format the image's or, with MUTABLE_FORMAT_BIT, one of the same texel size.
    constexpr const char* who = "vkrc::ImageView::create";
    const auto& r = ci.subresourceRange;
    auto range_fits = [](std::uint32_t base, std::uint32_t count, std::uint32_t total) {
        return base < total && (count == VK_REMAINING_MIP_LEVELS || (count != 0 && count <= total - base));
    };
    if (!range_fits(r.baseMipLevel, r.levelCount, image.mip_levels())) {
        throw UsageError(
            std::string(who) + ": mip levels " + std::to_string(r.baseMipLevel) + "+" +
            (r.levelCount == VK_REMAINING_MIP_LEVELS ? std::string("remaining") : std::to_string(r.levelCount)) +
            " are outside the image's " + std::to_string(image.mip_levels()) + " levels");
    }
    if (!range_fits(r.baseArrayLayer, r.layerCount, image.array_layers())) {
        throw UsageError(
            std::string(who) + ": array layers " + std::to_string(r.baseArrayLayer) + "+" +
            (r.layerCount == VK_REMAINING_ARRAY_LAYERS ? std::string("remaining") : std::to_string(r.layerCount)) +
            " are outside the image's " + std::to_string(image.array_layers()) + " layers");
    }
    if (ci.format != image.format()) {
        if (!(image.state()->flags & VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT)) {
            throw UsageError(std::string(who) + ": format " + detail::enum_text(ci.format) +
                             " differs from the image's " + detail::enum_text(image.format()) +
                             " and the image lacks VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT");
        }
        const std::uint32_t view_texel = format_texel_size(ci.format);
        const std::uint32_t image_texel = format_texel_size(image.format());
        if (view_texel != 0 && image_texel != 0 && view_texel != image_texel) {
            throw UsageError(std::string(who) + ": format " + detail::enum_text(ci.format) + " has " +
                             std::to_string(view_texel) + "-byte texels, the image's format " +
                             detail::enum_text(image.format()) + " has " + std::to_string(image_texel));
        }
    }
    detail::Ref<detail::ImageViewState> state(new detail::ImageViewState);
    const auto& device = image.device();
    check(device.fn().vkCreateImageView(device.vk(), &ci, nullptr, &state->handle), "vkCreateImageView");
    state->image = image;
    state->format = ci.format;
    state->range = ci.subresourceRange;
    state->ycbcr_conversion = info.ycbcr_conversion;
    return ImageView(detail::registered(std::move(state), device, detail::DescribedKind::image_view));
}

BufferView BufferView::create(const Buffer& buffer, const BufferViewCreateInfo& info) {
    detail::require_handle(buffer, "vkrc::BufferView::create", "the Buffer");
    if (info.format == VK_FORMAT_UNDEFINED) throw UsageError("vkrc::BufferView::create: format is VK_FORMAT_UNDEFINED");
    VkBufferViewCreateInfo ci{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO, info.next};
    ci.flags = info.flags;
    ci.buffer = buffer.vk();
    ci.format = info.format;
    ci.offset = info.offset;
    ci.range = info.range;
    detail::Ref<detail::BufferViewState> state(new detail::BufferViewState);
    const auto& device = buffer.device();
    check(device.fn().vkCreateBufferView(device.vk(), &ci, nullptr, &state->handle), "vkCreateBufferView");
    state->buffer = buffer;
    return BufferView(detail::registered(std::move(state), device, detail::DescribedKind::buffer_view));
}

ImageView ImageView::adopt(const Image& image, VkImageView view, VkFormat format,
                           const VkImageSubresourceRange& subresource_range, Ownership ownership) {
    auto state = detail::adopted_state<detail::ImageViewState, &detail::ImageViewState::image>(
        "vkrc::ImageView::adopt", image, "the Image", view, "VkImageView", ownership);
    state->format = format;
    state->range = subresource_range;
    return ImageView(detail::registered(std::move(state), image.device(), detail::DescribedKind::image_view, true));
}

BufferView BufferView::adopt(const Buffer& buffer, VkBufferView view, Ownership ownership) {
    return BufferView(
        detail::registered(detail::adopted_state<detail::BufferViewState, &detail::BufferViewState::buffer>(
                               "vkrc::BufferView::adopt", buffer, "the Buffer", view, "VkBufferView", ownership),
                           buffer.device(), detail::DescribedKind::buffer_view, true));
}

Sampler Sampler::adopt(const Device& device, VkSampler sampler, Ownership ownership) {
    return Sampler(
        detail::registered(detail::adopted_state<detail::SamplerState>("vkrc::Sampler::adopt", device, "the Device",
                                                                       sampler, "VkSampler", ownership),
                           device, detail::DescribedKind::sampler));
}

Sampler Sampler::create(const Device& device, const SamplerCreateInfo& info) {
    detail::require_handle(device, "vkrc::Sampler::create", "the Device");
    VkSamplerYcbcrConversionInfo conversion =
        conversion_info(device, info.ycbcr_conversion, info.next, "vkrc::Sampler::create");
    VkSamplerCreateInfo ci{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO, info.ycbcr_conversion ? &conversion : info.next};
    ci.flags = info.flags;
    ci.magFilter = info.mag_filter;
    ci.minFilter = info.min_filter;
    ci.mipmapMode = info.mipmap_mode;
    ci.addressModeU = info.address_mode_u;
    ci.addressModeV = info.address_mode_v;
    ci.addressModeW = info.address_mode_w;
    ci.mipLodBias = info.mip_lod_bias;
    ci.anisotropyEnable = info.anisotropy_enable ? VK_TRUE : VK_FALSE;
    ci.maxAnisotropy = info.max_anisotropy;
    ci.compareEnable = info.compare_enable ? VK_TRUE : VK_FALSE;
    ci.compareOp = info.compare_op;
    ci.minLod = info.min_lod;
    ci.maxLod = info.max_lod;
    ci.borderColor = info.border_color;
    ci.unnormalizedCoordinates = info.unnormalized_coordinates ? VK_TRUE : VK_FALSE;
    auto state =
        detail::created_state<detail::SamplerState, &DeviceFunctions::vkCreateSampler>(device, ci, "vkCreateSampler");
    state->ycbcr_conversion = info.ycbcr_conversion;
    return Sampler(detail::registered(std::move(state), device, detail::DescribedKind::sampler));
}

VKRC_END_NAMESPACE
