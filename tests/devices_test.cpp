// Physical-device features, format properties, selection by features and
// the default queue family; the generated extension function tables.
#include "support/vk_test.hpp"

#include <vkrc/extension_functions.hpp>

#include <algorithm>
#include <cstring>
#include <memory>
#include <string>

namespace {

using vkrc_test::ValidationLog;
using vkrc_test::VulkanTest;

bool has(const vkrc::List<vkrc::Text>& names, const char* name) {
    return std::find(names.begin(), names.end(), name) != names.end();
}

TEST_F(VulkanTest, FeaturesMatchTheDriversAnswer) {
    VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &f13};
    VkPhysicalDeviceVulkan11Features f11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES, &f12};
    VkPhysicalDeviceFeatures2 f{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f11};
    physical_device.fn().vkGetPhysicalDeviceFeatures2(physical_device.vk(), &f);
    const auto& features = physical_device.features();
    EXPECT_EQ(std::memcmp(&features.core, &f.features, sizeof f.features), 0);
    EXPECT_EQ(features.vulkan11.shaderDrawParameters, f11.shaderDrawParameters);
    EXPECT_EQ(features.vulkan11.multiview, f11.multiview);
    EXPECT_EQ(features.vulkan12.descriptorIndexing, f12.descriptorIndexing);
    EXPECT_EQ(features.vulkan12.bufferDeviceAddress, f12.bufferDeviceAddress);
    EXPECT_EQ(features.vulkan13.dynamicRendering, f13.dynamicRendering);
    EXPECT_EQ(features.vulkan13.maintenance4, f13.maintenance4);
    EXPECT_TRUE(features.vulkan13.synchronization2);
    EXPECT_EQ(features.vulkan11.pNext, nullptr);
    EXPECT_EQ(features.vulkan12.pNext, nullptr);
}

TEST_F(VulkanTest, FeaturesRequiredThatTheDeviceHasAreAccepted) {
    vkrc::DeviceRequirements req = vkrc_test::test_device_requirements();
    req.required_features = physical_device.features();
    EXPECT_TRUE(physical_device.unmet_requirements(req).empty());
    EXPECT_EQ(vkrc::PhysicalDevice::select(instance, req).vk(), physical_device.vk());
}

TEST_F(VulkanTest, FeaturesMissingAreNamedInTheRejection) {
    // The first of a few rarely offered features that the device lacks.
    struct Candidate {
        VkBool32 VkPhysicalDeviceFeatures::*member;
        const char* name;
    };
    const Candidate candidates[] = {{&VkPhysicalDeviceFeatures::sparseResidencyAliased, "sparseResidencyAliased"},
                                    {&VkPhysicalDeviceFeatures::sparseResidency16Samples, "sparseResidency16Samples"},
                                    {&VkPhysicalDeviceFeatures::shaderResourceMinLod, "shaderResourceMinLod"},
                                    {&VkPhysicalDeviceFeatures::sparseBinding, "sparseBinding"}};
    const auto& have = physical_device.features().core;
    auto lacking = std::find_if(std::begin(candidates), std::end(candidates),
                                [&](const Candidate& c) { return !(have.*c.member); });
    if (lacking == std::end(candidates)) GTEST_SKIP() << "the device has every candidate feature";
    vkrc::DeviceRequirements req = vkrc_test::test_device_requirements();
    req.required_features.core.*lacking->member = VK_TRUE;
    req.required_features.vulkan12.timelineSemaphore = VK_TRUE;  // present: not named
    try {
        vkrc::PhysicalDevice::select(instance, req);
        FAIL() << "selection should have failed";
    } catch (const vkrc::NoSuitableDeviceError& e) {
        std::string what = e.what();
        EXPECT_NE(what.find(std::string(physical_device.name()) + ": lacks feature " + lacking->name + " (Vulkan 1.0)"),
                  std::string::npos)
            << what;
        EXPECT_EQ(what.find("timelineSemaphore"), std::string::npos) << what;
    }
}

TEST_F(VulkanTest, FeaturesFormatPropertiesHaveTheCoreFlags) {
    VkFormatProperties core{};
    physical_device.fn().vkGetPhysicalDeviceFormatProperties(physical_device.vk(), VK_FORMAT_R8G8B8A8_UNORM, &core);
    auto props = physical_device.format_properties(VK_FORMAT_R8G8B8A8_UNORM);
    EXPECT_EQ(props.sType, VK_STRUCTURE_TYPE_FORMAT_PROPERTIES_3);
    EXPECT_EQ(props.pNext, nullptr);
    // The 64-bit flags have every 32-bit flag, at the same bit (and may add some).
    EXPECT_EQ(props.optimalTilingFeatures & core.optimalTilingFeatures, core.optimalTilingFeatures);
    EXPECT_EQ(props.bufferFeatures & core.bufferFeatures, core.bufferFeatures);
    EXPECT_TRUE(props.optimalTilingFeatures & VK_FORMAT_FEATURE_2_COLOR_ATTACHMENT_BIT);
}

TEST(Features, PortabilityEnumerationIsEnabledWhenTheLoaderOffersIt) {
    auto log = std::make_shared<ValidationLog>();
    auto instance = vkrc::Instance::create(vkrc_test::validated_instance_info(log));
    bool offered = has(vkrc::Instance::available_extensions(), VK_KHR_PORTABILITY_ENUMERATION_EXTENSION_NAME);
    EXPECT_EQ(instance.extension_enabled(VK_KHR_PORTABILITY_ENUMERATION_EXTENSION_NAME), offered);
    instance.reset();
    vkrc_test::expect_no_validation_messages(*log);
}

// A surface from VK_EXT_headless_surface, made through the extension table.
TEST(Features, DefaultQueueFamilyCanPresentToTheRequestedSurface) {
    if (!has(vkrc::Instance::available_extensions(), VK_EXT_HEADLESS_SURFACE_EXTENSION_NAME)) {
        GTEST_SKIP() << "the loader offers no VK_EXT_headless_surface";
    }
    auto log = std::make_shared<ValidationLog>();
    auto info = vkrc_test::validated_instance_info(log);
    info.enabled_extension_names = {VK_KHR_SURFACE_EXTENSION_NAME, VK_EXT_HEADLESS_SURFACE_EXTENSION_NAME};
    auto instance = vkrc::Instance::create(info);
    VkHeadlessSurfaceCreateInfoEXT surface_info{VK_STRUCTURE_TYPE_HEADLESS_SURFACE_CREATE_INFO_EXT};
    VkSurfaceKHR raw = VK_NULL_HANDLE;
    ASSERT_EQ(instance.ext_fn().vkCreateHeadlessSurfaceEXT(instance.vk(), &surface_info, nullptr, &raw), VK_SUCCESS);
    auto surface = vkrc::Surface::adopt(instance, raw, vkrc::Ownership::owned);
    auto req = vkrc_test::test_device_requirements();
    req.present_surface = surface.vk();
    auto physical = vkrc::PhysicalDevice::select(instance, req);
    int family = physical.default_queue_family();
    ASSERT_GE(family, 0);
    VkBool32 supported = VK_FALSE;
    instance.fn().vkGetPhysicalDeviceSurfaceSupportKHR(physical.vk(), static_cast<std::uint32_t>(family), surface.vk(),
                                                       &supported);
    EXPECT_TRUE(supported);
    physical.reset();
    surface.reset();
    instance.reset();
    vkrc_test::expect_no_validation_messages(*log);
}

TEST_F(VulkanTest, ExtensionFunctionsOfEnabledExtensionsAreLoaded) {
    // VK_EXT_debug_utils (enabled with validation) provides device-level commands.
    const auto& ext = device.ext_fn();
    auto raw = physical_device.fn().vkGetDeviceProcAddr(device.vk(), "vkSetDebugUtilsObjectNameEXT");
    EXPECT_EQ(reinterpret_cast<PFN_vkVoidFunction>(ext.vkSetDebugUtilsObjectNameEXT), raw);
    VkDebugUtilsObjectNameInfoEXT name{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
    name.objectType = VK_OBJECT_TYPE_DEVICE;
    name.objectHandle = reinterpret_cast<std::uint64_t>(device.vk());
    name.pObjectName = "ExtensionFunctions device";
    EXPECT_EQ(ext.vkSetDebugUtilsObjectNameEXT(device.vk(), &name), VK_SUCCESS);
    // Instance-level: the messenger commands.
    EXPECT_EQ(reinterpret_cast<PFN_vkVoidFunction>(instance.ext_fn().vkCreateDebugUtilsMessengerEXT),
              instance.global_fn().vkGetInstanceProcAddr(instance.vk(), "vkCreateDebugUtilsMessengerEXT"));
    // Loaded once: the same table every time.
    EXPECT_EQ(&device.ext_fn(), &ext);
}

TEST_F(VulkanTest, ExtensionFunctionsOfADeviceExtensionAreLoadedWhenEnabled) {
    if (!physical_device.supports_extension(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME)) {
        GTEST_SKIP() << "the device lacks VK_KHR_push_descriptor";
    }
    auto with_push = vkrc::Device::create(physical_device, {.enabled_extension_names = {"VK_KHR_push_descriptor"}});
    auto raw = physical_device.fn().vkGetDeviceProcAddr(with_push.vk(), "vkCmdPushDescriptorSetKHR");
    ASSERT_NE(raw, nullptr);
    EXPECT_EQ(reinterpret_cast<PFN_vkVoidFunction>(with_push.ext_fn().vkCmdPushDescriptorSetKHR), raw);
}

TEST_F(VulkanTest, ExtensionFunctionsPromotedToCoreAreLoadedByTheirCoreName) {
    // VK_KHR_draw_indirect_count is not enabled; Vulkan 1.2 has vkCmdDrawIndirectCount.
    auto core = physical_device.fn().vkGetDeviceProcAddr(device.vk(), "vkCmdDrawIndirectCount");
    EXPECT_EQ(reinterpret_cast<PFN_vkVoidFunction>(device.ext_fn().vkCmdDrawIndirectCountKHR), core);
}

TEST_F(VulkanTest, ExtensionFunctionsNotLoadedSayWhichExtensionTheyNeed) {
    const auto& ext = device.ext_fn();
#if VKRC_RUNTIME_CHECKS
    try {
        ext.vkCmdPushDescriptorSetKHR(VK_NULL_HANDLE, VK_PIPELINE_BIND_POINT_GRAPHICS, VK_NULL_HANDLE, 0, 0, nullptr);
        FAIL() << "an unloaded command must throw";
    } catch (const vkrc::UsageError& e) {
        std::string what = e.what();
        EXPECT_NE(what.find("vkCmdPushDescriptorSetKHR"), std::string::npos) << what;
        EXPECT_NE(what.find("VK_KHR_push_descriptor"), std::string::npos) << what;
    }
    EXPECT_THROW(instance.ext_fn().vkCreateHeadlessSurfaceEXT(instance.vk(), nullptr, nullptr, nullptr),
                 vkrc::UsageError);
#else
    EXPECT_EQ(ext.vkCmdPushDescriptorSetKHR, nullptr);
#endif
}

}  // namespace
