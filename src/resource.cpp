#include "vkrc/resource.hpp"

#include "object_state.hpp"
#include "enum_names.hpp"
#include "recent_answers.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
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
                  AllocatorView allocator) {
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
VkSamplerYcbcrConversionInfo conversion_info(const detail::Caller& caller, const Device& device,
                                             const SamplerYcbcrConversion& conversion, const void* next) {
    VkSamplerYcbcrConversionInfo info{VK_STRUCTURE_TYPE_SAMPLER_YCBCR_CONVERSION_INFO, next};
    if (!conversion) return info;
    caller.require(conversion.device() == device, "the SamplerYcbcrConversion belongs to another device");
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
    state->tiling = info.tiling;
    state->ownership = ownership;
    return state;
}

// Create-time checks against the device: its limits, enabled features and
// format properties (docs/validation.md lists each refusal with its VUID).
// Always on, not only with VKRC_RUNTIME_CHECKS: creation is no hot path, and
// they cost a few comparisons and, for an image, one format-properties query,
// little beside the creation and the allocation they guard.

// Concurrent sharing: two or more distinct queue families of the device
// (VUID-VkBufferCreateInfo-sharingMode-00914/01419, VUID-VkImageCreateInfo-sharingMode-00942/01420).
void check_sharing(const detail::Caller& caller, const Device& device, VkSharingMode mode,
                   const List<std::uint32_t>& families) {
    if (mode != VK_SHARING_MODE_CONCURRENT) return;  // exclusive: the list is ignored
    caller.require(families.size() >= 2, "concurrent sharing needs at least 2 queue_family_indices, got ",
                   families.size());
    const std::size_t count = device.physical_device().queue_families().size();
    for (std::size_t i = 0; i < families.size(); ++i) {
        caller.require(families[i] < count, "queue_family_indices[", i, "] is ", families[i], " but the device has ",
                       count, " queue families");
        for (std::size_t j = 0; j < i; ++j) {
            caller.require(families[j] != families[i], "queue family ", families[i],
                           " appears twice in queue_family_indices");
        }
    }
}

// The rules of image type, extent, flags, samples and layout that need no query.
void check_image_shape(const detail::Caller& caller, const ImageCreateInfo& info) {
    const VkExtent3D& e = info.extent;
    const VkImageType type = info.image_type;
    caller.require(type != VK_IMAGE_TYPE_1D || (e.height == 1 && e.depth == 1), "a VK_IMAGE_TYPE_1D image has extent ",
                   e, "; height and depth must be 1");
    caller.require(type != VK_IMAGE_TYPE_2D || e.depth == 1, "a VK_IMAGE_TYPE_2D image has extent ", e,
                   "; depth must be 1");
    caller.require(type != VK_IMAGE_TYPE_3D || info.array_layers == 1, "a VK_IMAGE_TYPE_3D image has array_layers ",
                   info.array_layers, "; it must be 1");
    const auto levels = static_cast<std::uint32_t>(std::bit_width(std::max({e.width, e.height, e.depth})));
    caller.require(info.mip_levels <= levels, "mip_levels ", info.mip_levels, " exceeds the ", levels, " levels a ", e,
                   " image can have");
    if (info.flags & VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT) {
        caller.require(type == VK_IMAGE_TYPE_2D && e.width == e.height && info.array_layers >= 6,
                       "CUBE_COMPATIBLE needs a square VK_IMAGE_TYPE_2D image with at least 6 layers, not ", type, " ",
                       e, " with ", info.array_layers);
    }
    caller.require(!(info.flags & VK_IMAGE_CREATE_2D_ARRAY_COMPATIBLE_BIT) || type == VK_IMAGE_TYPE_3D,
                   "2D_ARRAY_COMPATIBLE needs a VK_IMAGE_TYPE_3D image, not ", type);
    if (info.samples != VK_SAMPLE_COUNT_1_BIT) {
        caller.require(type == VK_IMAGE_TYPE_2D && !(info.flags & VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT) &&
                           info.mip_levels == 1 && info.tiling == VK_IMAGE_TILING_OPTIMAL,
                       "samples ", info.samples,
                       " needs a VK_IMAGE_TYPE_2D, non-cube, optimally tiled image of 1 mip level, not ", type, ", ",
                       info.mip_levels, " levels, ", info.tiling);
    }
    caller.require(
        info.initial_layout == VK_IMAGE_LAYOUT_UNDEFINED || info.initial_layout == VK_IMAGE_LAYOUT_PREINITIALIZED,
        "initial_layout ", info.initial_layout, " is neither UNDEFINED nor PREINITIALIZED");
}

constexpr VkImageUsageFlags attachment_usage =
    VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT |
    VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSIENT_ATTACHMENT_BIT;

// Usage against the rules and limits that are not the format's.
void check_image_usage(const detail::Caller& caller, const Device& device, const ImageCreateInfo& info) {
    if (info.usage & VK_IMAGE_USAGE_TRANSIENT_ATTACHMENT_BIT) {
        caller.require((info.usage & ~attachment_usage) == 0 && (info.usage & ~VK_IMAGE_USAGE_TRANSIENT_ATTACHMENT_BIT),
                       "usage ", detail::Hex{info.usage},
                       ": TRANSIENT_ATTACHMENT goes only with, and needs one of, COLOR_, DEPTH_STENCIL_ or "
                       "INPUT_ATTACHMENT");
    }
    const VkPhysicalDeviceLimits& limits = device.physical_device().properties().limits;
    if (info.usage & attachment_usage) {
        caller.require(
            info.extent.width <= limits.maxFramebufferWidth && info.extent.height <= limits.maxFramebufferHeight,
            "an attachment image of extent ", info.extent, " exceeds maxFramebufferWidth x maxFramebufferHeight ",
            limits.maxFramebufferWidth, "x", limits.maxFramebufferHeight);
    }
    caller.require(!(info.usage & VK_IMAGE_USAGE_STORAGE_BIT) || info.samples == VK_SAMPLE_COUNT_1_BIT ||
                       device.state()->enabled_features.core.shaderStorageImageMultisample,
                   "a STORAGE image with samples ", info.samples,
                   " needs the shaderStorageImageMultisample feature enabled");
}

// vkGetPhysicalDeviceImageFormatProperties for info's combination. It answers
// the same for the same arguments, and a program makes many images of few
// kinds, so each thread keeps the last few answers (no lock), keyed by the
// device's id: creation pays the query, which costs more than all of vkrc's
// own per-image work, once per kind rather than per image.
VkResult image_format_properties(const Device& device, const ImageCreateInfo& info, VkImageFormatProperties& p) {
    struct Question {
        std::uint64_t device_id = 0;  // 0: an empty slot
        VkFormat format{};
        VkImageType type{};
        VkImageTiling tiling{};
        VkImageUsageFlags usage = 0;
        VkImageCreateFlags flags = 0;
        bool operator==(const Question&) const = default;
    };
    struct Answer {
        VkResult result{};
        VkImageFormatProperties properties{};
    };
    thread_local detail::RecentAnswers<Question, Answer, 4> answers;
    const Question q{device.state()->id, info.format, info.image_type, info.tiling, info.usage, info.flags};
    if (const Answer* a = answers.find(q)) {
        p = a->properties;
        return a->result;
    }
    const PhysicalDevice& physical = device.physical_device();
    const VkResult r = physical.fn().vkGetPhysicalDeviceImageFormatProperties(physical.vk(), q.format, q.type, q.tiling,
                                                                              q.usage, q.flags, &p);
    if (r == VK_SUCCESS || r == VK_ERROR_FORMAT_NOT_SUPPORTED) answers.keep(q, {r, p});  // not an out-of-memory
    return r;
}

// What vkGetPhysicalDeviceImageFormatProperties allows for the image: the
// combination at all, then extent, levels, layers and samples.
void check_image_format(const detail::Caller& caller, const Device& device, const ImageCreateInfo& info) {
    VkImageFormatProperties p{};
    const VkResult r = image_format_properties(device, info, p);
    caller.require(r != VK_ERROR_FORMAT_NOT_SUPPORTED, "format ", info.format, " as a ", info.image_type, " with ",
                   info.tiling, ", usage ", detail::Hex{info.usage}, " and flags ", detail::Hex{info.flags},
                   " is not supported by the device (vkGetPhysicalDeviceImageFormatProperties)");
    check(r, "vkGetPhysicalDeviceImageFormatProperties");
    const VkExtent3D& e = info.extent;
    caller.require(e.width <= p.maxExtent.width && e.height <= p.maxExtent.height && e.depth <= p.maxExtent.depth,
                   "extent ", e, " exceeds the ", p.maxExtent, " maximum for ", info.format, " as a ", info.image_type);
    caller.require(info.mip_levels <= p.maxMipLevels, "mip_levels ", info.mip_levels, " exceeds the ", p.maxMipLevels,
                   " levels the device allows for ", info.format);
    caller.require(info.array_layers <= p.maxArrayLayers, "array_layers ", info.array_layers, " exceeds the ",
                   p.maxArrayLayers, " layers the device allows for ", info.format);
    caller.require((p.sampleCounts & info.samples) != 0, "samples ", info.samples, " not supported for ", info.format,
                   " with this usage and tiling (sampleCounts ", detail::Hex{p.sampleCounts}, ")");
}

// The view types an image of type and flags can be seen through (the view
// type compatibility table of VUID-VkImageViewCreateInfo-subResourceRange-01021,
// -image-01003, -image-06723 and -image-06727).
bool view_type_fits(VkImageType type, VkImageCreateFlags flags, VkImageViewType view) {
    switch (view) {
        case VK_IMAGE_VIEW_TYPE_1D:
        case VK_IMAGE_VIEW_TYPE_1D_ARRAY: return type == VK_IMAGE_TYPE_1D;
        case VK_IMAGE_VIEW_TYPE_2D:
        case VK_IMAGE_VIEW_TYPE_2D_ARRAY:
            return type == VK_IMAGE_TYPE_2D ||
                   (type == VK_IMAGE_TYPE_3D && (flags & VK_IMAGE_CREATE_2D_ARRAY_COMPATIBLE_BIT));
        case VK_IMAGE_VIEW_TYPE_CUBE:
        case VK_IMAGE_VIEW_TYPE_CUBE_ARRAY:
            return type == VK_IMAGE_TYPE_2D && (flags & VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT);
        case VK_IMAGE_VIEW_TYPE_3D: return type == VK_IMAGE_TYPE_3D;
        default: return false;
    }
}

// The layers a view's range counts in: the image's array layers, or for a 2D
// or 2D_ARRAY view of a 2D_ARRAY_COMPATIBLE 3D image the depth slices of its
// base level (VUID-VkImageViewCreateInfo-image-02724, -subresourceRange-02725).
// The caller has checked baseMipLevel.
std::uint32_t view_layer_total(const Image& image, const VkImageViewCreateInfo& ci) {
    const bool slices = image.image_type() == VK_IMAGE_TYPE_3D &&
                        (image.state()->flags & VK_IMAGE_CREATE_2D_ARRAY_COMPATIBLE_BIT) &&
                        (ci.viewType == VK_IMAGE_VIEW_TYPE_2D || ci.viewType == VK_IMAGE_VIEW_TYPE_2D_ARRAY);
    return slices ? std::max(1u, image.extent().depth >> ci.subresourceRange.baseMipLevel) : image.array_layers();
}

// View type against the image and the layers it covers.
void check_view_type(const detail::Caller& caller, const Device& device, const Image& image,
                     const VkImageViewCreateInfo& ci) {
    const VkImageType type = image.image_type();
    const VkImageCreateFlags flags = image.state()->flags;
    const VkImageViewType view = ci.viewType;
    const auto& r = ci.subresourceRange;
    caller.require(view_type_fits(type, flags, view), "view_type ", view, " cannot view a ", type, " image",
                   (flags & VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT) ? " (CUBE_COMPATIBLE)" : "");
    caller.require(view != VK_IMAGE_VIEW_TYPE_CUBE_ARRAY || device.state()->enabled_features.core.imageCubeArray,
                   "view_type VK_IMAGE_VIEW_TYPE_CUBE_ARRAY needs the imageCubeArray feature enabled");
    caller.require(image.samples() == VK_SAMPLE_COUNT_1_BIT || view == VK_IMAGE_VIEW_TYPE_2D ||
                       view == VK_IMAGE_VIEW_TYPE_2D_ARRAY,
                   "a view of an image with samples ", image.samples(), " must be 2D or 2D_ARRAY, not ", view);
    if (type == VK_IMAGE_TYPE_3D && view != VK_IMAGE_VIEW_TYPE_3D) {
        // The rule counts levelCount as given: VK_REMAINING_MIP_LEVELS is not 1.
        caller.require(r.levelCount == 1, "a ", view, " view of a 3D image needs levelCount 1, not ",
                       detail::Count{r.levelCount});
    }
    const std::uint32_t layers =
        r.layerCount == VK_REMAINING_ARRAY_LAYERS ? view_layer_total(image, ci) - r.baseArrayLayer : r.layerCount;
    const bool single = view == VK_IMAGE_VIEW_TYPE_1D || view == VK_IMAGE_VIEW_TYPE_2D || view == VK_IMAGE_VIEW_TYPE_3D;
    caller.require(!single || layers == 1, "a ", view, " view covers 1 layer, not ", layers);
    caller.require(view != VK_IMAGE_VIEW_TYPE_CUBE || layers == 6,
                   "a VK_IMAGE_VIEW_TYPE_CUBE view covers 6 layers, not ", layers);
    caller.require(view != VK_IMAGE_VIEW_TYPE_CUBE_ARRAY || layers % 6 == 0,
                   "a VK_IMAGE_VIEW_TYPE_CUBE_ARRAY view covers a multiple of 6 layers, not ", layers);
}

// The image's usage as the view's format allows it (VUID-VkImageViewCreateInfo-image-04441,
// -None-02273, -usage-02274/02275/02276/02277/02652).
void check_view_usage(const detail::Caller& caller, const Image& image, VkFormat format) {
    const VkImageUsageFlags usage = image.usage();
    constexpr VkImageUsageFlags view_usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT | attachment_usage;
    caller.require((usage & view_usage) != 0, "the image's usage ", detail::Hex{usage},
                   " has none of the usages an image view serves (SAMPLED, STORAGE or an attachment)");
    const VkFormatProperties3 props = image.device().physical_device().format_properties(format);
    const VkFormatFeatureFlags2 f =
        image.state()->tiling == VK_IMAGE_TILING_LINEAR ? props.linearTilingFeatures : props.optimalTilingFeatures;
    const auto lacks = [&](VkImageUsageFlags u, VkFormatFeatureFlags2 needs) { return (usage & u) && !(f & needs); };
    caller.require(
        f != 0 && !lacks(VK_IMAGE_USAGE_SAMPLED_BIT, VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_BIT) &&
            !lacks(VK_IMAGE_USAGE_STORAGE_BIT, VK_FORMAT_FEATURE_2_STORAGE_IMAGE_BIT) &&
            !lacks(VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, VK_FORMAT_FEATURE_2_COLOR_ATTACHMENT_BIT) &&
            !lacks(VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, VK_FORMAT_FEATURE_2_DEPTH_STENCIL_ATTACHMENT_BIT) &&
            !lacks(VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT,
                   VK_FORMAT_FEATURE_2_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_2_DEPTH_STENCIL_ATTACHMENT_BIT),
        "format ", format, " lacks the format features (", detail::Hex{f}, ") the image's usage ", detail::Hex{usage},
        " needs of a view");
}

// The range within the image, the format the image's or, with
// MUTABLE_FORMAT_BIT, one of the same texel size.
void check_view_range_and_format(const detail::Caller& caller, const Image& image, const VkImageViewCreateInfo& ci) {
    const auto& r = ci.subresourceRange;
    auto range_fits = [](std::uint32_t base, std::uint32_t count, std::uint32_t total) {
        return base < total && (count == VK_REMAINING_MIP_LEVELS || (count != 0 && count <= total - base));
    };
    caller.require(range_fits(r.baseMipLevel, r.levelCount, image.mip_levels()), "mip levels ", r.baseMipLevel, "+",
                   detail::Count{r.levelCount}, " are outside the image's ", image.mip_levels(), " levels");
    const std::uint32_t layers = view_layer_total(image, ci);
    caller.require(range_fits(r.baseArrayLayer, r.layerCount, layers), "array layers ", r.baseArrayLayer, "+",
                   detail::Count{r.layerCount}, " are outside the image's ", layers, " layers");
    if (ci.format != image.format()) {
        caller.require(image.state()->flags & VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT, "format ", ci.format,
                       " differs from the image's ", image.format(),
                       " and the image lacks VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT");
        const std::uint32_t view_texel = format_texel_size(ci.format);
        const std::uint32_t image_texel = format_texel_size(image.format());
        caller.require(view_texel == 0 || image_texel == 0 || view_texel == image_texel, "format ", ci.format, " has ",
                       view_texel, "-byte texels, the image's format ", image.format(), " has ", image_texel);
    }
}

// Sampler limits, features and the unnormalized-coordinates rules.
void check_sampler(const detail::Caller& caller, const Device& device, const SamplerCreateInfo& info) {
    const VkPhysicalDeviceLimits& limits = device.physical_device().properties().limits;
    const DeviceFeatures& features = device.state()->enabled_features;
    caller.require(std::fabs(info.mip_lod_bias) <= limits.maxSamplerLodBias, "mip_lod_bias ", info.mip_lod_bias,
                   " exceeds maxSamplerLodBias ", limits.maxSamplerLodBias);
    caller.require(info.max_lod >= info.min_lod, "max_lod ", info.max_lod, " is less than min_lod ", info.min_lod);
    if (info.anisotropy_enable) {
        caller.require(features.core.samplerAnisotropy,
                       "anisotropy_enable needs the samplerAnisotropy feature enabled");
        caller.require(info.max_anisotropy >= 1.0f && info.max_anisotropy <= limits.maxSamplerAnisotropy,
                       "max_anisotropy ", info.max_anisotropy, " is outside 1..maxSamplerAnisotropy ",
                       limits.maxSamplerAnisotropy);
    }
    for (VkSamplerAddressMode m : {info.address_mode_u, info.address_mode_v, info.address_mode_w}) {
        caller.require(m != VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE ||
                           features.vulkan12.samplerMirrorClampToEdge ||
                           device.extension_enabled(VK_KHR_SAMPLER_MIRROR_CLAMP_TO_EDGE_EXTENSION_NAME),
                       "address mode ", m,
                       " needs the samplerMirrorClampToEdge feature or VK_KHR_sampler_mirror_clamp_to_edge enabled");
    }
    if (!info.unnormalized_coordinates) return;
    caller.require(info.min_filter == info.mag_filter, "unnormalized_coordinates needs min_filter ", info.min_filter,
                   " and mag_filter ", info.mag_filter, " equal");
    caller.require(info.mipmap_mode == VK_SAMPLER_MIPMAP_MODE_NEAREST,
                   "unnormalized_coordinates needs mipmap_mode NEAREST, not ", info.mipmap_mode);
    caller.require(info.min_lod == 0.0f && info.max_lod == 0.0f,
                   "unnormalized_coordinates needs min_lod and max_lod 0, not ", info.min_lod, " and ", info.max_lod);
    for (VkSamplerAddressMode m : {info.address_mode_u, info.address_mode_v}) {
        caller.require(m == VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE || m == VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER,
                       "unnormalized_coordinates needs address modes U and V CLAMP_TO_EDGE or CLAMP_TO_BORDER, not ",
                       m);
    }
    caller.require(!info.anisotropy_enable && !info.compare_enable,
                   "unnormalized_coordinates excludes anisotropy_enable and compare_enable");
}

}  // namespace

Buffer Buffer::create(const Device& device, const BufferCreateInfo& info) {
    const detail::Caller caller{"vkrc::Buffer::create"};
    caller.require_handle(device, "the Device");
    caller.require(info.size != 0, "size is 0");
    caller.require(info.usage != 0, "usage is 0");
    constexpr VkBufferCreateFlags sparse = VK_BUFFER_CREATE_SPARSE_BINDING_BIT | VK_BUFFER_CREATE_SPARSE_RESIDENCY_BIT |
                                           VK_BUFFER_CREATE_SPARSE_ALIASED_BIT;
    caller.require(!(info.flags & sparse),
                   "sparse flags are not supported (vkrc binds one allocation to each buffer; create a sparse buffer "
                   "with vkCreateBuffer and bind it with vkQueueBindSparse)");
    caller.require(!(info.usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) ||
                       device.state()->enabled_features.vulkan12.bufferDeviceAddress,
                   "usage SHADER_DEVICE_ADDRESS needs the bufferDeviceAddress feature enabled");
    check_sharing(caller, device, info.sharing_mode, info.queue_family_indices);
    {
        // A size no heap can hold (a negative number cast to VkDeviceSize, a
        // product that wrapped) fails here with its value, not later with
        // an out-of-memory from the allocator's alignment arithmetic.
        const auto& memory = device.physical_device().memory_properties();
        VkDeviceSize largest = 0;
        for (std::uint32_t i = 0; i < memory.memoryHeapCount; ++i)
            largest = std::max(largest, memory.memoryHeaps[i].size);
        caller.require(info.size <= largest, "size ", info.size,
                       " is larger than every memory heap of the device (the largest has ", largest, " bytes)");
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
    const detail::Caller caller{"vkrc::Buffer::adopt"};
    caller.require_handle(device, "the Device");
    caller.require_not_null(buffer, "VkBuffer");
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
    const detail::Caller caller{"vkrc::Image::create"};
    caller.require_handle(device, "the Device");
    caller.require(info.format != VK_FORMAT_UNDEFINED, "format is VK_FORMAT_UNDEFINED");
    caller.require(info.extent.width != 0 && info.extent.height != 0 && info.extent.depth != 0,
                   "extent has a zero dimension");
    caller.require(info.mip_levels != 0 && info.array_layers != 0, "mip_levels and array_layers must be at least 1");
    caller.require(info.usage != 0, "usage is 0");
    constexpr VkImageCreateFlags sparse =
        VK_IMAGE_CREATE_SPARSE_BINDING_BIT | VK_IMAGE_CREATE_SPARSE_RESIDENCY_BIT | VK_IMAGE_CREATE_SPARSE_ALIASED_BIT;
    caller.require(!(info.flags & sparse),
                   "sparse flags are not supported (vkrc binds one allocation to each image; create a sparse image "
                   "with vkCreateImage and bind it with vkQueueBindSparse)");
    check_sharing(caller, device, info.sharing_mode, info.queue_family_indices);
    check_image_shape(caller, info);
    check_image_usage(caller, device, info);
    check_image_format(caller, device, info);
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
    const detail::Caller caller{"vkrc::Image::adopt"};
    caller.require_handle(device, "the Device");
    caller.require_not_null(image, "VkImage");
    auto state = image_state(device, info, ownership);
    state->handle = image;
    state->cleanup = std::move(cleanup);
    return Image(std::move(state));
}

ImageView ImageView::create(const Image& image, const ImageViewCreateInfo& info) {
    const detail::Caller caller{"vkrc::ImageView::create"};
    caller.require_handle(image, "the Image");
    VkSamplerYcbcrConversionInfo conversion = conversion_info(caller, image.device(), info.ycbcr_conversion, info.next);
    VkImageViewCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO, info.ycbcr_conversion ? &conversion : info.next};
    ci.flags = info.flags;
    ci.image = image.vk();
    ci.viewType = info.view_type;
    ci.format = info.format == VK_FORMAT_UNDEFINED ? image.format() : info.format;
    ci.components = info.components;
    ci.subresourceRange = info.subresource_range;
    if (ci.subresourceRange.aspectMask == 0) ci.subresourceRange.aspectMask = format_aspects(ci.format);
    check_view_range_and_format(caller, image, ci);
    check_view_type(caller, image.device(), image, ci);
    check_view_usage(caller, image, ci.format);
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
    const detail::Caller caller{"vkrc::BufferView::create"};
    caller.require_handle(buffer, "the Buffer");
    caller.require(info.format != VK_FORMAT_UNDEFINED, "format is VK_FORMAT_UNDEFINED");
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
        detail::Caller{"vkrc::ImageView::adopt"}, image, "the Image", view, "VkImageView", ownership);
    state->format = format;
    state->range = subresource_range;
    return ImageView(detail::registered(std::move(state), image.device(), detail::DescribedKind::image_view, true));
}

BufferView BufferView::adopt(const Buffer& buffer, VkBufferView view, Ownership ownership) {
    return BufferView(detail::registered(
        detail::adopted_state<detail::BufferViewState, &detail::BufferViewState::buffer>(
            detail::Caller{"vkrc::BufferView::adopt"}, buffer, "the Buffer", view, "VkBufferView", ownership),
        buffer.device(), detail::DescribedKind::buffer_view, true));
}

Sampler Sampler::adopt(const Device& device, VkSampler sampler, Ownership ownership) {
    return Sampler(
        detail::registered(detail::adopted_state<detail::SamplerState>(detail::Caller{"vkrc::Sampler::adopt"}, device,
                                                                       "the Device", sampler, "VkSampler", ownership),
                           device, detail::DescribedKind::sampler));
}

Sampler Sampler::create(const Device& device, const SamplerCreateInfo& info) {
    const detail::Caller caller{"vkrc::Sampler::create"};
    caller.require_handle(device, "the Device");
    check_sampler(caller, device, info);
    VkSamplerYcbcrConversionInfo conversion = conversion_info(caller, device, info.ycbcr_conversion, info.next);
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
