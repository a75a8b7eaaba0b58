// Shared test support: every test that touches Vulkan runs with the Khronos
// validation layer, and any warning or error it reports fails the test.
#pragma once

#include <vkrc/vkrc.hpp>

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace vkrc_test {

// One RGBA8 pixel as read back from an image.
using Rgba = std::array<std::uint8_t, 4>;

// Whether every channel of actual is within one of expected: a blend or a
// conversion whose exact result is halfway (0.5 of 255) may round either way
// (NVIDIA gives 127 where lavapipe gives 128).
::testing::AssertionResult within_one(const Rgba& actual, const Rgba& expected);

// Collects validation messages from any thread.
class ValidationLog {
public:
    void add(const vkrc::DebugMessage& m) {
        std::lock_guard lock(mutex_);
        messages_.push_back(std::string(m.message_id_name ? m.message_id_name : "-") + ": " + m.message);
    }
    std::vector<std::string> take() {
        std::lock_guard lock(mutex_);
        return std::exchange(messages_, {});
    }
    // Drops messages the test provoked on purpose, all of which must carry id.
    std::size_t take_expected(const std::string& id);

private:
    std::mutex mutex_;
    std::vector<std::string> messages_;
};

// InstanceCreateInfo with validation on and messages routed into log.
vkrc::InstanceCreateInfo validated_instance_info(const std::shared_ptr<ValidationLog>& log);

// The device the tests run on: VKRC_TEST_DEVICE (a name substring) or the best.
vkrc::DeviceRequirements test_device_requirements();

// The set layout of shaders/sample_texels.comp: a combined image sampler at
// binding 0, the storage buffer it writes at binding 1.
vkrc::DescriptorSetLayout sample_texels_set_layout(const vkrc::Device& device);

// Fixture: a validated instance, the chosen physical device and a device with
// one graphics+compute queue. TearDown drops them all and fails the test on
// any validation message, including those reported at destruction (leaks).
class VulkanTest : public ::testing::Test {
protected:
    void SetUp() override;
    void TearDown() override;
    // What SetUp does, from the given instance info.
    void create_all(const vkrc::InstanceCreateInfo& instance_info);
    // Drops the fixture's handles (tests that check destruction order call it).
    void release_all();

    std::shared_ptr<ValidationLog> log = std::make_shared<ValidationLog>();
    vkrc::Instance instance;
    vkrc::PhysicalDevice physical_device;
    vkrc::Device device;
    vkrc::Queue queue;
};

// The same with the validation layer's synchronization validation on: a
// missing or too narrow barrier is a reported hazard, and fails the test.
class SyncValidatedTest : public VulkanTest {
protected:
    void SetUp() override;
};

// Asserts that log has no messages (prints them otherwise).
void expect_no_validation_messages(ValidationLog& log);

}  // namespace vkrc_test
