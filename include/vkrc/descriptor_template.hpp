// Descriptor update templates: one call writes a whole set (or push
// descriptors) from a block of application data laid out as the entries say.
#pragma once

#include "vkrc/pipeline.hpp"

#include "vkrc/detail/list.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
class DescriptorUpdateTemplateState;
}  // namespace detail

// Mirrors VkDescriptorUpdateTemplateCreateInfo.
struct DescriptorUpdateTemplateCreateInfo {
    // Optional (reserved by Vulkan, default none).
    VkDescriptorUpdateTemplateCreateFlags flags = 0;
    // Required, not empty: where each run of descriptors sits in the data
    // (offset and stride in bytes). Read during create().
    List<VkDescriptorUpdateTemplateEntry> entries{};
    // Optional (default DESCRIPTOR_SET: DescriptorSet::update_with_template).
    // PUSH_DESCRIPTORS_KHR: CommandBuffer::push_descriptor_set_with_template,
    // which needs VK_KHR_push_descriptor enabled on the device.
    VkDescriptorUpdateTemplateType template_type = VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_DESCRIPTOR_SET;
    // Required: the layout of the sets it writes (for push descriptors, the
    // layout of pipeline_layout's set `set`). The template keeps it alive.
    DescriptorSetLayout descriptor_set_layout{};
    // For PUSH_DESCRIPTORS_KHR only (ignored otherwise): where the pushed
    // set goes. The template keeps the pipeline layout alive.
    VkPipelineBindPoint pipeline_bind_point = VK_PIPELINE_BIND_POINT_GRAPHICS;
    PipelineLayout pipeline_layout{};
    std::uint32_t set = 0;
    // Optional pNext chain. Read during create().
    const void* next = nullptr;
};

// A VkDescriptorUpdateTemplate; keeps its layouts (and so its Device) alive.
class DescriptorUpdateTemplate : public DeviceChild<detail::DescriptorUpdateTemplateState, VkDescriptorUpdateTemplate> {
public:
    // Throws UsageError for no entries, a missing layout, a push template
    // without a pipeline layout or without VK_KHR_push_descriptor, or
    // layouts of another device.
    static DescriptorUpdateTemplate create(const Device& device, const DescriptorUpdateTemplateCreateInfo& info);
    // A template made by other code; info describes it as its creation did
    // (its type, layouts, set and entries are kept, and checked as create()
    // checks them; flags and next are ignored; the entries count the
    // references of DescriptorSet::update_with_template, so without them
    // its writes keep nothing alive). Owned: vkrc destroys it
    // after the GPU is done; borrowed: its maker does, after every vkrc
    // handle to it has gone.
    static DescriptorUpdateTemplate adopt(const Device& device, VkDescriptorUpdateTemplate update_template,
                                          const DescriptorUpdateTemplateCreateInfo& info, Ownership ownership);

    VkDescriptorUpdateTemplateType template_type() const VKRC_UNCHECKED_NOEXCEPT;
    const DescriptorSetLayout& descriptor_set_layout() const VKRC_UNCHECKED_NOEXCEPT;
    // For push templates: the pipeline layout and set they push to (empty / 0 otherwise).
    const PipelineLayout& pipeline_layout() const VKRC_UNCHECKED_NOEXCEPT;
    std::uint32_t set() const VKRC_UNCHECKED_NOEXCEPT;

private:
    using DeviceChild::DeviceChild;
};

namespace detail {

class DescriptorUpdateTemplateState final : public DeviceChildState<VkDescriptorUpdateTemplate> {
public:
    static constexpr const char* type_name = "vkrc::DescriptorUpdateTemplate";
    ~DescriptorUpdateTemplateState() override;
    VkDescriptorUpdateTemplateType type = VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_DESCRIPTOR_SET;
    DescriptorSetLayout set_layout;
    PipelineLayout pipeline_layout;
    std::uint32_t set = 0;
    // The entries, to find the objects an update writes (descriptor references).
    List<VkDescriptorUpdateTemplateEntry> entries;
};

}  // namespace detail

inline VkDescriptorUpdateTemplateType DescriptorUpdateTemplate::template_type() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::DescriptorUpdateTemplate::template_type").type;
}
inline const DescriptorSetLayout& DescriptorUpdateTemplate::descriptor_set_layout() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::DescriptorUpdateTemplate::descriptor_set_layout").set_layout;
}
inline const PipelineLayout& DescriptorUpdateTemplate::pipeline_layout() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::DescriptorUpdateTemplate::pipeline_layout").pipeline_layout;
}
inline std::uint32_t DescriptorUpdateTemplate::set() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::DescriptorUpdateTemplate::set").set;
}

VKRC_END_NAMESPACE
