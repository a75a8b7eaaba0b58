#include "vk_test.hpp"

#include <cstdlib>
#include <memory>
#include <mutex>
#include <string>

namespace vkrc_test {

::testing::AssertionResult within_one(const Rgba& actual, const Rgba& expected) {
    for (std::size_t c = 0; c < actual.size(); ++c) {
        if (std::abs(int(actual[c]) - int(expected[c])) > 1) {
            return ::testing::AssertionFailure()
                   << "pixel {" << int(actual[0]) << ", " << int(actual[1]) << ", " << int(actual[2]) << ", "
                   << int(actual[3]) << "} differs by more than one in channel " << c << " from {" << int(expected[0])
                   << ", " << int(expected[1]) << ", " << int(expected[2]) << ", " << int(expected[3]) << "}";
        }
    }
    return ::testing::AssertionSuccess();
}

std::size_t ValidationLog::take_expected(const std::string& id) {
    std::lock_guard lock(mutex_);
    std::size_t before = messages_.size();
    std::erase_if(messages_, [&](const std::string& m) { return m.find(id) != std::string::npos; });
    return before - messages_.size();
}

vkrc::InstanceCreateInfo validated_instance_info(const std::shared_ptr<ValidationLog>& log) {
    vkrc::InstanceCreateInfo info;
    info.application_name = "vkrc tests";
    info.validation = true;
    info.debug_callback = [log](const vkrc::DebugMessage& m) {
        vkrc::print_debug_message(m);
        log->add(m);
    };
    return info;
}

vkrc::DeviceRequirements test_device_requirements() {
    vkrc::DeviceRequirements req;
    if (const char* name = std::getenv("VKRC_TEST_DEVICE")) req.name_contains = name;
    return req;
}

vkrc::DescriptorSetLayout sample_texels_set_layout(const vkrc::Device& device) {
    return vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{.binding = 0,
                               .descriptor_type = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                               .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT},
                              {.binding = 1,
                               .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                               .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT}}});
}

void VulkanTest::SetUp() { create_all(validated_instance_info(log)); }

void SyncValidatedTest::SetUp() {
    const VkValidationFeatureEnableEXT enable = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
    VkValidationFeaturesEXT features{};
    features.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
    features.enabledValidationFeatureCount = 1;
    features.pEnabledValidationFeatures = &enable;
    auto info = validated_instance_info(log);
    info.next = &features;
    create_all(info);
}

void VulkanTest::create_all(const vkrc::InstanceCreateInfo& instance_info) {
    instance = vkrc::Instance::create(instance_info);
    physical_device = vkrc::PhysicalDevice::select(instance, test_device_requirements());
    device = vkrc::Device::create(physical_device);
    queue = device.default_queue();
}

void VulkanTest::release_all() {
    queue = {};
    device.reset();
    physical_device.reset();
    instance.reset();
}

void VulkanTest::TearDown() {
    release_all();
    expect_no_validation_messages(*log);
}

void expect_no_validation_messages(ValidationLog& log) {
    auto messages = log.take();
    EXPECT_TRUE(messages.empty()) << messages.size() << " validation message(s), first: " << messages.front();
}

}  // namespace vkrc_test

#if defined(__SANITIZE_ADDRESS__)
#  include <dlfcn.h>
namespace {
// The loader unloads the driver and the layer at vkDestroyInstance; leaks
// inside them would then be reported from "<unknown module>" and could not be
// told from vkrc's. Pinning them keeps their names for lsan.supp.
[[maybe_unused]] const bool pinned_driver_modules = [] {
    for (const char* lib : {"libvulkan_lvp.so", "libVkLayer_khronos_validation.so"}) {
        dlopen(lib, RTLD_LAZY | RTLD_LOCAL | RTLD_NODELETE);
    }
    return true;
}();
}  // namespace
#endif
