// Sampler Y'CbCr conversions (Vulkan 1.1 core): how samplers and image views
// of multi-planar video formats turn Y'CbCr into RGB. A Sampler or ImageView
// made with one (SamplerCreateInfo / ImageViewCreateInfo::ycbcr_conversion)
// keeps it alive.
#pragma once

#include "vkrc/device.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
class SamplerYcbcrConversionState;
}  // namespace detail

// Mirrors VkSamplerYcbcrConversionCreateInfo. The device needs the
// samplerYcbcrConversion feature (DeviceCreateInfo::vulkan11_features), and
// the format the matching VK_FORMAT_FEATURE_*_CHROMA_* and filter features.
struct SamplerYcbcrConversionCreateInfo {
    // Required: a format with a Y'CbCr model (e.g. VK_FORMAT_G8_B8R8_2PLANE_420_UNORM).
    VkFormat format = VK_FORMAT_UNDEFINED;
    // Optional (default BT.709 with narrow range, the usual video encoding).
    VkSamplerYcbcrModelConversion ycbcr_model = VK_SAMPLER_YCBCR_MODEL_CONVERSION_YCBCR_709;
    VkSamplerYcbcrRange ycbcr_range = VK_SAMPLER_YCBCR_RANGE_ITU_NARROW;
    // Optional (default identity).
    VkComponentMapping components{};
    // Optional (default midpoint); the format must support the chosen location.
    VkChromaLocation x_chroma_offset = VK_CHROMA_LOCATION_MIDPOINT;
    VkChromaLocation y_chroma_offset = VK_CHROMA_LOCATION_MIDPOINT;
    // Optional (default nearest, which every Y'CbCr format supports).
    VkFilter chroma_filter = VK_FILTER_NEAREST;
    // Optional (default false).
    bool force_explicit_reconstruction = false;
    // Optional pNext chain. Read during create().
    const void* next = nullptr;
};

// A VkSamplerYcbcrConversion; keeps its Device alive.
class SamplerYcbcrConversion : public DeviceChild<detail::SamplerYcbcrConversionState, VkSamplerYcbcrConversion> {
public:
    static SamplerYcbcrConversion create(const Device& device, const SamplerYcbcrConversionCreateInfo& info);
    // A conversion made by other code for format. Owned: vkrc destroys it
    // after the GPU is done; borrowed: its maker does, after every vkrc handle to it has gone.
    static SamplerYcbcrConversion adopt(const Device& device, VkSamplerYcbcrConversion conversion, VkFormat format,
                                        Ownership ownership);

    VkFormat format() const VKRC_UNCHECKED_NOEXCEPT;

private:
    using DeviceChild::DeviceChild;
};

namespace detail {

class SamplerYcbcrConversionState final : public DeviceChildState<VkSamplerYcbcrConversion> {
public:
    static constexpr const char* type_name = "vkrc::SamplerYcbcrConversion";
    ~SamplerYcbcrConversionState() override;
    VkFormat format = VK_FORMAT_UNDEFINED;
};

}  // namespace detail

inline VkFormat SamplerYcbcrConversion::format() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::SamplerYcbcrConversion::format").format;
}

VKRC_END_NAMESPACE
