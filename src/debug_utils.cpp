#include "vkrc/debug_utils.hpp"

#include "object_state.hpp"
#include "debug_message.hpp"

#include <string>

VKRC_BEGIN_NAMESPACE

namespace detail {
DebugMessengerState::~DebugMessengerState() {
    if (owns_handle()) instance.fn().vkDestroyDebugUtilsMessengerEXT(instance.vk(), handle, nullptr);
}
}  // namespace detail

namespace {
void require_debug_utils(const detail::Caller& caller, const Instance& instance) {
    caller.require_handle(instance, "the Instance");
    caller.require(instance.extension_enabled(VK_EXT_DEBUG_UTILS_EXTENSION_NAME),
                   "the instance was created without VK_EXT_debug_utils");
}
}  // namespace

DebugMessenger DebugMessenger::create(const Instance& instance, const DebugMessengerCreateInfo& info) {
    const detail::Caller caller{"vkrc::DebugMessenger::create"};
    require_debug_utils(caller, instance);
    caller.require(static_cast<bool>(info.callback), "the callback is empty");
    // The state exists first: its callback's address is the user data.
    detail::Ref<detail::DebugMessengerState> state(new detail::DebugMessengerState);
    state->instance = instance;
    state->callback = info.callback;
    VkDebugUtilsMessengerCreateInfoEXT ci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT, info.next};
    ci.messageSeverity = info.severities;
    ci.messageType = info.types;
    ci.pfnUserCallback = detail::debug_trampoline;
    ci.pUserData = &state->callback;
    check(instance.fn().vkCreateDebugUtilsMessengerEXT(instance.vk(), &ci, nullptr, &state->handle),
          "vkCreateDebugUtilsMessengerEXT");
    return DebugMessenger(std::move(state));
}

DebugMessenger DebugMessenger::adopt(const Instance& instance, VkDebugUtilsMessengerEXT messenger,
                                     Ownership ownership) {
    const detail::Caller caller{"vkrc::DebugMessenger::adopt"};
    require_debug_utils(caller, instance);
    return DebugMessenger(detail::adopted_state<detail::DebugMessengerState, &detail::DebugMessengerState::instance>(
        caller, instance, "the Instance", messenger, "VkDebugUtilsMessengerEXT", ownership));
}

void set_name(const Device& device, VkObjectType type, std::uint64_t handle, const char* name) {
    // Null when the instance did not enable VK_EXT_debug_utils (see device.cpp).
    auto set = device.fn().vkSetDebugUtilsObjectNameEXT;
    if (!set) return;
    VkDebugUtilsObjectNameInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
    info.objectType = type;
    info.objectHandle = handle;
    info.pObjectName = name;
    check(set(device.vk(), &info), "vkSetDebugUtilsObjectNameEXT");
}

VKRC_END_NAMESPACE
