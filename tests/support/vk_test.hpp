// Shared test support: every test that touches Vulkan runs with the Khronos
// validation layer, and any warning or error it reports fails the test.
#pragma once

#include <vkrc/vkrc.hpp>

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

namespace vkrc_test {

// One RGBA8 pixel as read back from an image.
using Rgba = std::array<std::uint8_t, 4>;

// Whether every channel of actual is within one of expected: a blend or a
// conversion whose exact result is halfway (0.5 of 255) may round either way
// (NVIDIA gives 127 where lavapipe gives 128).
::testing::AssertionResult within_one(const Rgba& actual, const Rgba& expected);

// Collects validation messages from any thread. Every message must be
// accounted for: taken as expected (by exact id and count) or reported by
// expect_no_validation_messages; one still here when the log goes (after the
// instance, whose callback holds it) fails the running test.
class ValidationLog {
public:
    ValidationLog() = default;
    ValidationLog(const ValidationLog&) = delete;
    ValidationLog& operator=(const ValidationLog&) = delete;
    ~ValidationLog();

    void add(const vkrc::DebugMessage& m);
    // Every message as "id: text", emptying the log.
    std::vector<std::string> take();
    // Removes the messages whose id is exactly id (messages the test provoked
    // on purpose, or a layer false positive named where it is taken); fails
    // unless there were exactly count of them.
    ::testing::AssertionResult take_expected(std::string_view id, std::size_t count);

private:
    struct Message {
        std::string id;
        std::string text;
    };
    std::mutex mutex_;
    std::vector<Message> messages_;
};

// InstanceCreateInfo with core and synchronization validation on (and
// GPU-assisted validation with VKRC_TEST_GPU_AV=1) and messages routed into
// log. Its next chain is a static VkValidationFeaturesEXT: a caller that
// chains its own structs must chain it after them.
vkrc::InstanceCreateInfo validated_instance_info(const std::shared_ptr<ValidationLog>& log);

// The device the tests run on: VKRC_TEST_DEVICE (a name substring) or the best.
vkrc::DeviceRequirements test_device_requirements();

// The seed of a randomized test: VKRC_TEST_SEED when set (to replay a run),
// else one drawn at random once per process. Printed with the test's name at
// each call, so that a failing run's output says how to replay it.
std::uint32_t test_seed();

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

// A gate only the host opens: work submitted behind it waits on the GPU for
// a timeline value that open() signals from the host (vkSignalSemaphore), so
// whatever a test drops before open() is certainly still in use by it.
class GpuGate {
public:
    explicit GpuGate(const vkrc::Device& device)
        : device_(device), semaphore_(vkrc::Semaphore::create_timeline(device, 0)) {}
    GpuGate(const GpuGate&) = delete;
    GpuGate& operator=(const GpuGate&) = delete;
    // Waits for the device to be idle: lavapipe (Mesa 25) may still touch a
    // semaphore of a submission after its fence has signalled, and
    // destroying the gate right after the fence wait (which the spec allows)
    // crashed its queue thread now and then.
    ~GpuGate();
    // The wait to put first in a submission.
    vkrc::SemaphoreSubmit wait() const { return {semaphore_, 1}; }
    // Submits cmd behind the gate, signalling fence when it is done.
    void submit(const vkrc::Queue& queue, const vkrc::CommandBuffer& cmd, const vkrc::Fence& fence) const;
    void open() const { semaphore_.signal(1); }

private:
    vkrc::Device device_;
    vkrc::Semaphore semaphore_;
};

// Counts a device's descriptor set allocations and frees, through its
// function table, while it lives; with a capacity, vkAllocateDescriptorSets
// refuses sets beyond it (VK_ERROR_OUT_OF_POOL_MEMORY), as a full pool does
// (lavapipe's pools never run out). One at a time.
class CountSetCalls {
public:
    explicit CountSetCalls(const vkrc::Device& device, int capacity = 1 << 30);
    CountSetCalls(const CountSetCalls&) = delete;
    CountSetCalls& operator=(const CountSetCalls&) = delete;
    ~CountSetCalls();
    int allocated() const;  // sets the driver allocated
    int refused() const;    // allocations refused for the capacity
    int freed() const;      // sets freed

private:
    vkrc::DeviceFunctions& fn_;
};

// Asserts that log has no messages (prints them otherwise).
void expect_no_validation_messages(ValidationLog& log);

// Runs f, which must throw UsageError whose message contains every part.
void expect_usage_error(const std::function<void()>& f, std::initializer_list<const char*> parts);

}  // namespace vkrc_test
