#include "support/vk_test.hpp"

#include <cstring>
#include <memory>
#include <string>

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
    instance.reset();
    vkrc_test::expect_no_validation_messages(*log);
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
            EXPECT_TRUE(line.contains("lacks extension VK_VKRC_no_such_extension")) << line.c_str();
            EXPECT_TRUE(line.contains("needs 9.0.0")) << line.c_str();
        }
        EXPECT_NE(std::string(e.what()).find("rejected"), std::string::npos);
    }
    instance.reset();
    vkrc_test::expect_no_validation_messages(*log);
}

TEST(Instance, DebugMessagesReachTheCallback) {
    auto log = std::make_shared<ValidationLog>();
    auto instance = vkrc::Instance::create(vkrc_test::validated_instance_info(log));
    VkDebugUtilsMessengerCallbackDataEXT data{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CALLBACK_DATA_EXT};
    data.pMessageIdName = "vkrc-test-message";
    data.pMessage = "hello from the test";
    instance.fn().vkSubmitDebugUtilsMessageEXT(instance.vk(), VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT,
                                               VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT, &data);
    EXPECT_TRUE(log->take_expected("vkrc-test-message", 1));
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
        EXPECT_STREQ(e.what(), "vkAllocateMemory failed: VK_ERROR_OUT_OF_DEVICE_MEMORY");
    }
    EXPECT_THROW(vkrc::check(VK_ERROR_DEVICE_LOST, "vkQueueSubmit2"), vkrc::DeviceLostError);
    // Every vkrc error is a std::exception; copies share the message.
    const vkrc::DeviceLostError lost("vkQueueSubmit2");
    const std::exception& as_std = lost;
    EXPECT_STREQ(as_std.what(), "vkQueueSubmit2 failed: VK_ERROR_DEVICE_LOST");
    const vkrc::Error copy = lost;
    EXPECT_EQ(copy.what(), lost.what());
    EXPECT_EQ(copy.result(), VK_ERROR_DEVICE_LOST);
    const vkrc::UsageError usage(std::string("vkrc::Buffer::create: ") + "size is 0");
    EXPECT_STREQ(static_cast<const std::exception&>(usage).what(), "vkrc::Buffer::create: size is 0");
}

TEST(Errors, TextIsSharedAndComparable) {
    vkrc::Text empty;
    EXPECT_STREQ(empty.c_str(), "");
    EXPECT_TRUE(empty.empty());
    vkrc::Text hello = "hello, world";
    vkrc::Text copy = hello;
    EXPECT_EQ(copy.c_str(), hello.c_str());
    EXPECT_EQ(hello.size(), 12u);
    EXPECT_TRUE(hello == "hello, world");
    EXPECT_FALSE(hello == "hello");
    EXPECT_TRUE(hello.contains("o, w"));
    EXPECT_FALSE(hello.contains("xyz"));
    EXPECT_EQ(vkrc::Text(std::string("abc")), vkrc::Text("abc", 3));
}

TEST(Errors, StatusesAreReturnedNotThrown) {
    for (VkResult status : {VK_SUCCESS, VK_TIMEOUT, VK_NOT_READY, VK_SUBOPTIMAL_KHR, VK_INCOMPLETE}) {
        EXPECT_EQ(vkrc::check(status, "call"), status);
    }
    EXPECT_STREQ(vkrc::to_string(VK_ERROR_OUT_OF_DATE_KHR), "VK_ERROR_OUT_OF_DATE_KHR");
    EXPECT_EQ(vkrc::to_string(static_cast<VkResult>(-123456)), nullptr);
    EXPECT_STREQ(vkrc::Error(static_cast<VkResult>(-123456), "vkCall").what(), "vkCall failed: VkResult(-123456)");
}

}  // namespace
