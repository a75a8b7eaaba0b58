// Private data slots (Vulkan 1.3 core): one 64-bit value per Vulkan object
// of the device, for the application's own bookkeeping.
#pragma once

#include "vkrc/device.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
class PrivateDataSlotState;
}  // namespace detail

// Mirrors VkPrivateDataSlotCreateInfo. Every member is optional. The device
// needs the privateData feature (DeviceCreateInfo::vulkan13_features).
struct PrivateDataSlotCreateInfo {
    // Reserved by Vulkan (default none).
    VkPrivateDataSlotCreateFlags flags = 0;
    // Optional pNext chain. Read during create().
    const void* next = nullptr;
};

// A VkPrivateDataSlot; keeps its Device alive. Vulkan synchronises set and
// get internally, so any thread may call them.
class PrivateDataSlot : public DeviceChild<detail::PrivateDataSlotState, VkPrivateDataSlot> {
public:
    static PrivateDataSlot create(const Device& device, const PrivateDataSlotCreateInfo& info = {});
    // A slot made by other code. Ownership as for SamplerYcbcrConversion::adopt.
    static PrivateDataSlot adopt(const Device& device, VkPrivateDataSlot slot, Ownership ownership);

    // vkSetPrivateData / vkGetPrivateData for a raw handle of this slot's
    // device (or the VkDevice itself) of object_type, e.g.
    //     slot.set(VK_OBJECT_TYPE_BUFFER, buffer.vk(), 42);
    // get returns 0 for an object nothing was set on.
    template <class VkHandle>
    void set(VkObjectType object_type, VkHandle object, std::uint64_t data) const {
        set_bits(object_type, detail::handle_bits(object), data);
    }
    template <class VkHandle>
    std::uint64_t get(VkObjectType object_type, VkHandle object) const {
        return get_bits(object_type, detail::handle_bits(object));
    }

private:
    using DeviceChild::DeviceChild;
    void set_bits(VkObjectType object_type, std::uint64_t object, std::uint64_t data) const;
    std::uint64_t get_bits(VkObjectType object_type, std::uint64_t object) const;
};

namespace detail {

class PrivateDataSlotState final : public DeviceChildState<VkPrivateDataSlot> {
public:
    static constexpr const char* type_name = "vkrc::PrivateDataSlot";
    ~PrivateDataSlotState() override;
};

}  // namespace detail

VKRC_END_NAMESPACE
