#include "vkrc/functions.hpp"

#include "vkrc/error.hpp"

VKRC_BEGIN_NAMESPACE

GlobalFunctions GlobalFunctions::load(PFN_vkGetInstanceProcAddr get_instance_proc_addr) {
    GlobalFunctions f;
    f.vkGetInstanceProcAddr = get_instance_proc_addr ? get_instance_proc_addr : ::vkGetInstanceProcAddr;
#define VKRC_GLOBAL_FUNCTION(name) \
  f.name = reinterpret_cast<PFN_##name>(f.vkGetInstanceProcAddr(VK_NULL_HANDLE, #name));
#include "vkrc/detail/function_list.inl"
    if (!f.vkCreateInstance) {
        throw Error(VK_ERROR_INITIALIZATION_FAILED, "vkGetInstanceProcAddr(vkCreateInstance)");
    }
    return f;
}

InstanceFunctions InstanceFunctions::load(PFN_vkGetInstanceProcAddr get_instance_proc_addr, VkInstance instance) {
    InstanceFunctions f;
#define VKRC_INSTANCE_FUNCTION(name) f.name = reinterpret_cast<PFN_##name>(get_instance_proc_addr(instance, #name));
#include "vkrc/detail/function_list.inl"
    return f;
}

DeviceFunctions DeviceFunctions::load(PFN_vkGetDeviceProcAddr get_device_proc_addr, VkDevice device) {
    DeviceFunctions f;
#define VKRC_DEVICE_FUNCTION(name) f.name = reinterpret_cast<PFN_##name>(get_device_proc_addr(device, #name));
#include "vkrc/detail/function_list.inl"
    return f;
}

VKRC_END_NAMESPACE
