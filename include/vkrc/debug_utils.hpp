// VK_EXT_debug_utils: debug messengers as handles, and object names.
#pragma once

#include "vkrc/device.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
class DebugMessengerState;
}  // namespace detail

// Mirrors VkDebugUtilsMessengerCreateInfoEXT.
struct DebugMessengerCreateInfo {
    // Required. Copied into the messenger: what it refers to must outlive it.
    // Called from whichever thread made the call that produced the message.
    DebugCallback callback{};
    // Which messages reach the callback (default warnings and errors).
    VkDebugUtilsMessageSeverityFlagsEXT severities =
        VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    // Default general, validation and performance messages.
    VkDebugUtilsMessageTypeFlagsEXT types = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                                            VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                                            VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    // Chained into the create-info. Null: none. Read during create() only.
    const void* next = nullptr;
};

// A debug-utils messenger; keeps its Instance alive. An instance may have any
// number, each with its own callback and filter (besides the one that
// InstanceCreateInfo::debug_callback installs).
class DebugMessenger : public VulkanObject<detail::DebugMessengerState, VkDebugUtilsMessengerEXT> {
public:
    // The instance must have enabled VK_EXT_debug_utils.
    static DebugMessenger create(const Instance& instance, const DebugMessengerCreateInfo& info);
    // Wraps a messenger made elsewhere. With Ownership::owned vkrc destroys it.
    static DebugMessenger adopt(const Instance& instance, VkDebugUtilsMessengerEXT messenger, Ownership ownership);

    const Instance& instance() const VKRC_UNCHECKED_NOEXCEPT;

private:
    using VulkanObject::VulkanObject;
};

// The VkObjectType of a Vulkan handle type (VK_OBJECT_TYPE_UNKNOWN for others).
template <class VkHandle>
inline constexpr VkObjectType object_type_of = VK_OBJECT_TYPE_UNKNOWN;
#define VKRC_OBJECT_TYPE(handle, type) \
  template <>                          \
  inline constexpr VkObjectType object_type_of<handle> = type;
VKRC_OBJECT_TYPE(VkInstance, VK_OBJECT_TYPE_INSTANCE)
VKRC_OBJECT_TYPE(VkPhysicalDevice, VK_OBJECT_TYPE_PHYSICAL_DEVICE)
VKRC_OBJECT_TYPE(VkDevice, VK_OBJECT_TYPE_DEVICE)
VKRC_OBJECT_TYPE(VkQueue, VK_OBJECT_TYPE_QUEUE)
VKRC_OBJECT_TYPE(VkSemaphore, VK_OBJECT_TYPE_SEMAPHORE)
VKRC_OBJECT_TYPE(VkCommandBuffer, VK_OBJECT_TYPE_COMMAND_BUFFER)
VKRC_OBJECT_TYPE(VkFence, VK_OBJECT_TYPE_FENCE)
VKRC_OBJECT_TYPE(VkDeviceMemory, VK_OBJECT_TYPE_DEVICE_MEMORY)
VKRC_OBJECT_TYPE(VkBuffer, VK_OBJECT_TYPE_BUFFER)
VKRC_OBJECT_TYPE(VkImage, VK_OBJECT_TYPE_IMAGE)
VKRC_OBJECT_TYPE(VkEvent, VK_OBJECT_TYPE_EVENT)
VKRC_OBJECT_TYPE(VkQueryPool, VK_OBJECT_TYPE_QUERY_POOL)
VKRC_OBJECT_TYPE(VkBufferView, VK_OBJECT_TYPE_BUFFER_VIEW)
VKRC_OBJECT_TYPE(VkImageView, VK_OBJECT_TYPE_IMAGE_VIEW)
VKRC_OBJECT_TYPE(VkShaderModule, VK_OBJECT_TYPE_SHADER_MODULE)
VKRC_OBJECT_TYPE(VkPipelineCache, VK_OBJECT_TYPE_PIPELINE_CACHE)
VKRC_OBJECT_TYPE(VkPipelineLayout, VK_OBJECT_TYPE_PIPELINE_LAYOUT)
VKRC_OBJECT_TYPE(VkRenderPass, VK_OBJECT_TYPE_RENDER_PASS)
VKRC_OBJECT_TYPE(VkPipeline, VK_OBJECT_TYPE_PIPELINE)
VKRC_OBJECT_TYPE(VkDescriptorSetLayout, VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT)
VKRC_OBJECT_TYPE(VkSampler, VK_OBJECT_TYPE_SAMPLER)
VKRC_OBJECT_TYPE(VkDescriptorPool, VK_OBJECT_TYPE_DESCRIPTOR_POOL)
VKRC_OBJECT_TYPE(VkDescriptorSet, VK_OBJECT_TYPE_DESCRIPTOR_SET)
VKRC_OBJECT_TYPE(VkFramebuffer, VK_OBJECT_TYPE_FRAMEBUFFER)
VKRC_OBJECT_TYPE(VkCommandPool, VK_OBJECT_TYPE_COMMAND_POOL)
VKRC_OBJECT_TYPE(VkSamplerYcbcrConversion, VK_OBJECT_TYPE_SAMPLER_YCBCR_CONVERSION)
VKRC_OBJECT_TYPE(VkDescriptorUpdateTemplate, VK_OBJECT_TYPE_DESCRIPTOR_UPDATE_TEMPLATE)
VKRC_OBJECT_TYPE(VkPrivateDataSlot, VK_OBJECT_TYPE_PRIVATE_DATA_SLOT)
VKRC_OBJECT_TYPE(VkSurfaceKHR, VK_OBJECT_TYPE_SURFACE_KHR)
VKRC_OBJECT_TYPE(VkSwapchainKHR, VK_OBJECT_TYPE_SWAPCHAIN_KHR)
VKRC_OBJECT_TYPE(VkDebugUtilsMessengerEXT, VK_OBJECT_TYPE_DEBUG_UTILS_MESSENGER_EXT)
#undef VKRC_OBJECT_TYPE

// Names an object for validation messages, debuggers and captures
// (vkSetDebugUtilsObjectNameEXT). Does nothing unless the instance enabled
// VK_EXT_debug_utils. name: null clears the name; it is copied.
void set_name(const Device& device, VkObjectType type, std::uint64_t handle, const char* name);

// The same for a vkrc object (anything with vk(): Buffer, Pipeline, Queue...)
// or a raw handle of a type object_type_of knows, made from device.
template <class Object>
void set_name(const Device& device, const Object& object, const char* name) {
    if constexpr (requires { object.vk(); }) {
        set_name(device, object.vk(), name);
    } else {
        static_assert(object_type_of<Object> != VK_OBJECT_TYPE_UNKNOWN, "vkrc::set_name: not a Vulkan handle type");
        set_name(device, object_type_of<Object>, detail::handle_bits(object), name);
    }
}

namespace detail {

class DebugMessengerState final : public VulkanObjectState<VkDebugUtilsMessengerEXT> {
public:
    static constexpr const char* type_name = "vkrc::DebugMessenger";
    ~DebugMessengerState() override;
    Instance instance;
    DebugCallback callback;  // the messenger's user data: the state never moves
};

}  // namespace detail

inline const Instance& DebugMessenger::instance() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::DebugMessenger::instance").instance;
}

VKRC_END_NAMESPACE
