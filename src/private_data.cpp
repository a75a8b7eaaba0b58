#include "vkrc/private_data.hpp"

#include "object_state.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {

PrivateDataSlotState::~PrivateDataSlotState() {
    destroy_owned<&DeviceFunctions::vkDestroyPrivateDataSlot>(*this, device);
}

}  // namespace detail

PrivateDataSlot PrivateDataSlot::adopt(const Device& device, VkPrivateDataSlot slot, Ownership ownership) {
    return PrivateDataSlot(detail::adopted_state<detail::PrivateDataSlotState>(
        detail::Caller{"vkrc::PrivateDataSlot::adopt"}, device, "the Device", slot, "VkPrivateDataSlot", ownership));
}

PrivateDataSlot PrivateDataSlot::create(const Device& device, const PrivateDataSlotCreateInfo& info) {
    detail::Caller("vkrc::PrivateDataSlot::create").require_handle(device, "the Device");
    VkPrivateDataSlotCreateInfo ci{VK_STRUCTURE_TYPE_PRIVATE_DATA_SLOT_CREATE_INFO, info.next, info.flags};
    return PrivateDataSlot(
        detail::created_state<detail::PrivateDataSlotState, &DeviceFunctions::vkCreatePrivateDataSlot>(
            device, ci, "vkCreatePrivateDataSlot"));
}

void PrivateDataSlot::set_bits(VkObjectType object_type, std::uint64_t object, std::uint64_t data) const {
    VKRC_REQUIRE_STATE("vkrc::PrivateDataSlot::set");
    const auto& d = state_->device;
    check(d.fn().vkSetPrivateData(d.vk(), object_type, object, state_->handle, data), "vkSetPrivateData");
}

std::uint64_t PrivateDataSlot::get_bits(VkObjectType object_type, std::uint64_t object) const {
    VKRC_REQUIRE_STATE("vkrc::PrivateDataSlot::get");
    const auto& d = state_->device;
    std::uint64_t data = 0;
    d.fn().vkGetPrivateData(d.vk(), object_type, object, state_->handle, &data);
    return data;
}

VKRC_END_NAMESPACE
