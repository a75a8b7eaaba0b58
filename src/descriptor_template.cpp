#include "vkrc/descriptor_template.hpp"

#include "object_state.hpp"

#include <string>

VKRC_BEGIN_NAMESPACE

namespace detail {

// A push template may be referred to by an open command buffer: the serial holds the drop.
DescriptorUpdateTemplateState::~DescriptorUpdateTemplateState() {
    destroy_owned<&DeviceFunctions::vkDestroyDescriptorUpdateTemplate>(*this, device);
}

}  // namespace detail

namespace {

// adopt() passes need_entries false: the template exists, its entries are not read.
void check_template_info(const detail::Caller& caller, const Device& device,
                         const DescriptorUpdateTemplateCreateInfo& info, bool need_entries) {
    caller.require_handle(device, "the Device");
    caller.require(!need_entries || !info.entries.empty(), "entries is empty");
    caller.require(static_cast<bool>(info.descriptor_set_layout), "descriptor_set_layout is empty");
    caller.require(info.descriptor_set_layout.device() == device, "descriptor_set_layout belongs to another device");
    if (info.template_type != VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_PUSH_DESCRIPTORS_KHR) return;
    caller.require(device.extension_enabled(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME),
                   "a PUSH_DESCRIPTORS_KHR template needs VK_KHR_push_descriptor enabled on the device");
    caller.require(static_cast<bool>(info.pipeline_layout), "a push template needs pipeline_layout");
    caller.require(info.pipeline_layout.device() == device, "pipeline_layout belongs to another device");
}

// What the template was made for: its type, its set layout and, for a push
// template, the pipeline layout and set; the entries (the only copy that may throw).
void keep_template_info(detail::DescriptorUpdateTemplateState& s, const DescriptorUpdateTemplateCreateInfo& info) {
    s.type = info.template_type;
    s.set_layout = info.descriptor_set_layout;
    s.entries = info.entries;
    if (info.template_type == VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_PUSH_DESCRIPTORS_KHR) {
        s.pipeline_layout = info.pipeline_layout;
        s.set = info.set;
    }
}

}  // namespace

DescriptorUpdateTemplate DescriptorUpdateTemplate::create(const Device& device,
                                                          const DescriptorUpdateTemplateCreateInfo& info) {
    check_template_info(detail::Caller{"vkrc::DescriptorUpdateTemplate::create"}, device, info, true);
    const bool push = info.template_type == VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_PUSH_DESCRIPTORS_KHR;
    VkDescriptorUpdateTemplateCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_UPDATE_TEMPLATE_CREATE_INFO, info.next};
    ci.flags = info.flags;
    ci.descriptorUpdateEntryCount = static_cast<std::uint32_t>(info.entries.size());
    ci.pDescriptorUpdateEntries = info.entries.data();
    ci.templateType = info.template_type;
    ci.descriptorSetLayout = info.descriptor_set_layout.vk();
    if (push) {
        ci.pipelineBindPoint = info.pipeline_bind_point;
        ci.pipelineLayout = info.pipeline_layout.vk();
        ci.set = info.set;
    }
    auto s = detail::created_state<detail::DescriptorUpdateTemplateState,
                                   &DeviceFunctions::vkCreateDescriptorUpdateTemplate>(
        device, ci, "vkCreateDescriptorUpdateTemplate");
    keep_template_info(*s, info);
    return DescriptorUpdateTemplate(std::move(s));
}

DescriptorUpdateTemplate DescriptorUpdateTemplate::adopt(const Device& device,
                                                         VkDescriptorUpdateTemplate update_template,
                                                         const DescriptorUpdateTemplateCreateInfo& info,
                                                         Ownership ownership) {
    const detail::Caller caller{"vkrc::DescriptorUpdateTemplate::adopt"};
    check_template_info(caller, device, info, false);
    auto s = detail::adopted_state<detail::DescriptorUpdateTemplateState>(caller, device, "the Device", update_template,
                                                                          "VkDescriptorUpdateTemplate", ownership);
    keep_template_info(*s, info);
    return DescriptorUpdateTemplate(std::move(s));
}

VKRC_END_NAMESPACE
