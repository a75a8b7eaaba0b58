// Function tables for every command of every platform-neutral extension in
// vk.xml, generated at build time (scripts/gen_registry_tables.py).
//
// Not included by vkrc.hpp: the tables name several hundred commands, which
// every translation unit would parse (bench/header_cost). Include this header
// where they are called:
//     device.ext_fn().vkCmdPushDescriptorSetKHR(cmd.vk(), ...);
#pragma once

#include "vkrc/functions.hpp"

VKRC_BEGIN_NAMESPACE

// Each table is loaded on the first ext_fn() call, so that programs that do not
// use them pay nothing.

// Commands that take a VkInstance or VkPhysicalDevice (Instance::ext_fn()).
// Loaded when the instance enabled an extension that provides the command, or
// its api_version includes the core command the command became; commands of
// device extensions are loaded whenever the loader offers them (a physical
// device that supports the extension may be called). A slot that is not
// loaded holds, when vkrc was built with VKRC_RUNTIME_CHECKS, a function that
// throws UsageError naming the command and its extensions; otherwise null.
struct InstanceExtensionFunctions {
#define VKRC_INSTANCE_EXTENSION_FUNCTION(name) PFN_##name name = nullptr;
#include "vkrc/detail/extension_function_list.inl"
};

// Commands that take a VkDevice, VkQueue or VkCommandBuffer (Device::ext_fn()).
// Loaded through vkGetDeviceProcAddr when the device (or, for instance
// extensions such as VK_EXT_debug_utils, the instance) enabled an extension
// that provides the command, or the device's version includes the core
// command it became. Unloaded slots as in InstanceExtensionFunctions.
struct DeviceExtensionFunctions {
#define VKRC_DEVICE_EXTENSION_FUNCTION(name) PFN_##name name = nullptr;
#include "vkrc/detail/extension_function_list.inl"
};

VKRC_END_NAMESPACE
