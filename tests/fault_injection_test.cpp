// For every failable Vulkan call a scenario makes, run it again with that
// call failing: it must end in vkrc::Error carrying the injected result (or
// carry on where vkrc handles the failure itself), never crash, and leave
// nothing behind: the validation layer's object tracker reports leaked Vulkan
// objects at vkDestroyInstance, LeakSanitizer reports host memory in the ASan
// build.
#include "support/fault_injection.hpp"
#include "support/vk_test.hpp"

#include <array>
#include <cstdio>

namespace {

namespace faults = vkrc_test::faults;

constexpr std::array<VkResult, 4> injected_errors{VK_ERROR_OUT_OF_HOST_MEMORY, VK_ERROR_OUT_OF_DEVICE_MEMORY,
                                                  VK_ERROR_INITIALIZATION_FAILED, VK_ERROR_DEVICE_LOST};

// Setup plus three frames of everything vkrc wraps so far.
void scenario(const std::shared_ptr<vkrc_test::ValidationLog>& log) {
    auto info = vkrc_test::validated_instance_info(log);
    info.get_instance_proc_addr = faults::get_instance_proc_addr();
    auto instance = vkrc::Instance::create(info);
    auto physical_device = vkrc::PhysicalDevice::select(instance, vkrc_test::test_device_requirements());
    auto device = vkrc::Device::create(physical_device);
    auto queue = device.default_queue();
    for (int frame = 0; frame < 3; ++frame) {
        VkSubmitInfo2 empty{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
        queue.submit({&empty, 1});
        device.collect_garbage();
    }
    queue.wait_idle();
    device.wait_idle();
}

TEST(FaultInjection, EveryFailableCallFailsCleanly) {
    auto log = std::make_shared<vkrc_test::ValidationLog>();
    faults::arm(0, VK_SUCCESS);
    scenario(log);
    const std::uint64_t points = faults::failable_calls();
    vkrc_test::expect_no_validation_messages(*log);
    ASSERT_GT(points, 10u) << "the wrapper does not see vkrc's calls";

    std::uint64_t thrown = 0;
    for (std::uint64_t k = 1; k <= points; ++k) {
        const VkResult error = injected_errors[k % injected_errors.size()];
        faults::arm(k, error);
        try {
            scenario(log);
        } catch (const vkrc::Error& e) {
            ++thrown;
            EXPECT_TRUE(faults::fired());
            EXPECT_EQ(e.result(), error) << "call " << k << " (" << faults::fired_in() << "): " << e.what();
            if (error == VK_ERROR_DEVICE_LOST) {
                EXPECT_NE(dynamic_cast<const vkrc::DeviceLostError*>(&e), nullptr) << e.what();
            }
        }
        EXPECT_TRUE(faults::fired()) << "call " << k << " was not reached on the second run";
        auto messages = log->take();
        EXPECT_TRUE(messages.empty()) << "injecting " << vkrc::to_string(error) << " into call " << k << " ("
                                      << faults::fired_in() << "): " << messages.front();
    }
    faults::arm(0, VK_SUCCESS);
    std::printf("fault injection: %llu injection points exercised, %llu ended in vkrc::Error\n",
                static_cast<unsigned long long>(points), static_cast<unsigned long long>(thrown));
    EXPECT_GT(thrown, 0u);
}

}  // namespace
