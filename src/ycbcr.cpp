#include "vkrc/ycbcr.hpp"

#include "object_state.hpp"

#include <string>

VKRC_BEGIN_NAMESPACE

namespace detail {

SamplerYcbcrConversionState::~SamplerYcbcrConversionState() {
    destroy_owned<&DeviceFunctions::vkDestroySamplerYcbcrConversion>(*this, device);
}

}  // namespace detail

SamplerYcbcrConversion SamplerYcbcrConversion::adopt(const Device& device, VkSamplerYcbcrConversion conversion,
                                                     VkFormat format, Ownership ownership) {
    const detail::Caller caller{"vkrc::SamplerYcbcrConversion::adopt"};
    // Before the state exists: once it holds an owned conversion, a throw would destroy it.
    caller.require(format != VK_FORMAT_UNDEFINED, "format is VK_FORMAT_UNDEFINED");
    auto state = detail::adopted_state<detail::SamplerYcbcrConversionState>(caller, device, "the Device", conversion,
                                                                            "VkSamplerYcbcrConversion", ownership);
    state->format = format;
    return SamplerYcbcrConversion(std::move(state));
}

SamplerYcbcrConversion SamplerYcbcrConversion::create(const Device& device,
                                                      const SamplerYcbcrConversionCreateInfo& info) {
    const detail::Caller caller{"vkrc::SamplerYcbcrConversion::create"};
    caller.require_handle(device, "the Device");
    caller.require(info.format != VK_FORMAT_UNDEFINED, "format is VK_FORMAT_UNDEFINED");
    VkSamplerYcbcrConversionCreateInfo ci{VK_STRUCTURE_TYPE_SAMPLER_YCBCR_CONVERSION_CREATE_INFO, info.next};
    ci.format = info.format;
    ci.ycbcrModel = info.ycbcr_model;
    ci.ycbcrRange = info.ycbcr_range;
    ci.components = info.components;
    ci.xChromaOffset = info.x_chroma_offset;
    ci.yChromaOffset = info.y_chroma_offset;
    ci.chromaFilter = info.chroma_filter;
    ci.forceExplicitReconstruction = info.force_explicit_reconstruction ? VK_TRUE : VK_FALSE;
    auto state =
        detail::created_state<detail::SamplerYcbcrConversionState, &DeviceFunctions::vkCreateSamplerYcbcrConversion>(
            device, ci, "vkCreateSamplerYcbcrConversion");
    state->format = info.format;
    return SamplerYcbcrConversion(std::move(state));
}

VKRC_END_NAMESPACE
