#include "support/vk_test.hpp"

#include <cstring>

namespace {

using vkrc_test::ValidationLog;

// Fails, never skips, when there is no usable Vulkan device: a machine
// without a driver must not look green.
TEST(Environment, VulkanDeviceIsPresent) {
    auto log = std::make_shared<ValidationLog>();
    auto instance = vkrc::Instance::create(vkrc_test::validated_instance_info(log));
    auto devices = instance.physical_devices();
    ASSERT_FALSE(devices.empty()) << "no Vulkan physical device: install mesa-vulkan-drivers (lavapipe)";
    auto chosen = vkrc::PhysicalDevice::select(instance, vkrc_test::test_device_requirements());
    std::printf("test device: %s (Vulkan %u.%u)\n", chosen.name(), VK_API_VERSION_MAJOR(chosen.properties().apiVersion),
                VK_API_VERSION_MINOR(chosen.properties().apiVersion));
    chosen.reset();
    instance.reset();
    vkrc_test::expect_no_validation_messages(*log);
}

TEST(Environment, ValidationLayerIsInstalled) {
    auto layers = vkrc::Instance::available_layers();
    EXPECT_NE(std::find(layers.begin(), layers.end(), "VK_LAYER_KHRONOS_validation"), layers.end());
}

TEST(Instance, CpuDevicesAreAccepted) {
    auto log = std::make_shared<ValidationLog>();
    auto instance = vkrc::Instance::create(vkrc_test::validated_instance_info(log));
    for (auto& device : instance.physical_devices()) {
        if (device.properties().deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU) continue;
        EXPECT_TRUE(device.unmet_requirements({}).empty()) << device.name();
    }
}

TEST(Instance, SelectionSaysWhyEachDeviceWasRejected) {
    auto log = std::make_shared<ValidationLog>();
    auto instance = vkrc::Instance::create(vkrc_test::validated_instance_info(log));
    vkrc::DeviceRequirements req;
    req.required_extensions = {"VK_VKRC_no_such_extension"};
    req.min_api_version = VK_MAKE_API_VERSION(0, 9, 0, 0);
    try {
        vkrc::PhysicalDevice::select(instance, req);
        FAIL() << "selection should have failed";
    } catch (const vkrc::NoSuitableDeviceError& e) {
        ASSERT_EQ(e.rejections().size(), instance.physical_devices().size());
        for (const auto& line : e.rejections()) {
            EXPECT_NE(line.find("lacks extension VK_VKRC_no_such_extension"), std::string::npos) << line;
            EXPECT_NE(line.find("needs 9.0.0"), std::string::npos) << line;
        }
        EXPECT_NE(std::string(e.what()).find("rejected"), std::string::npos);
    }
}

TEST(Instance, DebugMessagesReachTheCallback) {
    auto log = std::make_shared<ValidationLog>();
    auto instance = vkrc::Instance::create(vkrc_test::validated_instance_info(log));
    VkDebugUtilsMessengerCallbackDataEXT data{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CALLBACK_DATA_EXT};
    data.pMessageIdName = "vkrc-test-message";
    data.pMessage = "hello from the test";
    instance.fn().vkSubmitDebugUtilsMessageEXT(instance.vk(), VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT,
                                               VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT, &data);
    EXPECT_EQ(log->take_expected("vkrc-test-message"), 1u);
    instance.reset();
    vkrc_test::expect_no_validation_messages(*log);
}

TEST(Instance, AdoptedBorrowedInstanceIsNotDestroyed) {
    auto log = std::make_shared<ValidationLog>();
    auto owner = vkrc::Instance::create(vkrc_test::validated_instance_info(log));
    {
        auto borrowed = vkrc::Instance::adopt(owner.vk(), vkrc::Ownership::borrowed, owner.api_version());
        EXPECT_EQ(borrowed.vk(), owner.vk());
        EXPECT_FALSE(borrowed.physical_devices().empty());
    }
    // Still usable: the borrowed wrapper did not destroy it.
    EXPECT_FALSE(owner.physical_devices().empty());
    owner.reset();
    vkrc_test::expect_no_validation_messages(*log);
}

TEST(Instance, AdoptedOwnedInstanceIsDestroyed) {
    auto global = vkrc::GlobalFunctions::load();
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.apiVersion = VK_API_VERSION_1_3;
    VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    info.pApplicationInfo = &app;
    const char* layer = "VK_LAYER_KHRONOS_validation";
    info.enabledLayerCount = 1;
    info.ppEnabledLayerNames = &layer;
    VkInstance raw = VK_NULL_HANDLE;
    ASSERT_EQ(global.vkCreateInstance(&info, nullptr, &raw), VK_SUCCESS);
    auto instance = vkrc::Instance::adopt(raw, vkrc::Ownership::owned, VK_API_VERSION_1_3);
    EXPECT_EQ(instance.vk(), raw);
    // Dropping it destroys the instance; LeakSanitizer and the loader would
    // report the instance otherwise.
}

TEST(Errors, FailuresThrowWithTheResultAndTheCall) {
    try {
        vkrc::check(VK_ERROR_OUT_OF_DEVICE_MEMORY, "vkAllocateMemory");
        FAIL();
    } catch (const vkrc::Error& e) {
        EXPECT_EQ(e.result(), VK_ERROR_OUT_OF_DEVICE_MEMORY);
        EXPECT_STREQ(e.call(), "vkAllocateMemory");
        EXPECT_EQ(e.code().category(), vkrc::vk_result_category());
        EXPECT_NE(std::string(e.what()).find("vkAllocateMemory failed"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("VK_ERROR_OUT_OF_DEVICE_MEMORY"), std::string::npos) << e.what();
    }
    EXPECT_THROW(vkrc::check(VK_ERROR_DEVICE_LOST, "vkQueueSubmit2"), vkrc::DeviceLostError);
    const std::system_error& as_system = vkrc::DeviceLostError("x");
    EXPECT_EQ(as_system.code(), vkrc::make_error_code(VK_ERROR_DEVICE_LOST));
}

TEST(Errors, StatusesAreReturnedNotThrown) {
    for (VkResult status : {VK_SUCCESS, VK_TIMEOUT, VK_NOT_READY, VK_SUBOPTIMAL_KHR, VK_INCOMPLETE}) {
        EXPECT_EQ(vkrc::check(status, "call"), status);
    }
    EXPECT_STREQ(vkrc::to_string(VK_ERROR_OUT_OF_DATE_KHR), "VK_ERROR_OUT_OF_DATE_KHR");
    EXPECT_EQ(vkrc::to_string(static_cast<VkResult>(-123456)), nullptr);
    EXPECT_EQ(vkrc::make_error_code(static_cast<VkResult>(-123456)).message(), "VkResult(-123456)");
}

}  // namespace
