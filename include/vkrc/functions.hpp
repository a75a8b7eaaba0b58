// Function tables: every Vulkan entry point vkrc calls, loaded once.
//
// Device-level functions come from vkGetDeviceProcAddr, so calls skip the
// loader's dispatch trampoline. The tables are public: call any function that
// vkrc does not wrap with the raw handles, e.g.
//     device.fn().vkCmdSetLineWidth(cmd.vk(), 2.0f);
#pragma once

#include "vkrc/config.hpp"

#include <vulkan/vulkan_core.h>

VKRC_BEGIN_NAMESPACE

// Functions callable without an instance.
struct GlobalFunctions {
    PFN_vkGetInstanceProcAddr vkGetInstanceProcAddr = nullptr;
#define VKRC_GLOBAL_FUNCTION(name) PFN_##name name = nullptr;
#include "vkrc/detail/function_list.inl"

    // Loads through get_instance_proc_addr (the loader's when null). Passing
    // another entry point is how tests wrap every call vkrc makes.
    static GlobalFunctions load(PFN_vkGetInstanceProcAddr get_instance_proc_addr = nullptr);
};

// Instance-level functions (physical devices, surfaces, debug messengers).
// Extension functions that the instance did not enable are null.
struct InstanceFunctions {
#define VKRC_INSTANCE_FUNCTION(name) PFN_##name name = nullptr;
#include "vkrc/detail/function_list.inl"

    static InstanceFunctions load(PFN_vkGetInstanceProcAddr get_instance_proc_addr, VkInstance instance);
};

// Device-level functions, including every vkCmd*. Functions of extensions or
// versions the device does not provide are null.
struct DeviceFunctions {
#define VKRC_DEVICE_FUNCTION(name) PFN_##name name = nullptr;
#include "vkrc/detail/function_list.inl"

    static DeviceFunctions load(PFN_vkGetDeviceProcAddr get_device_proc_addr, VkDevice device);
};

VKRC_END_NAMESPACE
