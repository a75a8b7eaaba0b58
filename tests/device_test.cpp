#include "support/vk_test.hpp"
#include "support/wrapped_allocator.hpp"

#include <algorithm>
#include <array>
#include <memory>
#include <span>
#include <string>
#include <thread>
#include <vector>

namespace {

using vkrc_test::ValidationLog;
using vkrc_test::VulkanTest;

struct Chain {
    vkrc::Instance instance;
    vkrc::PhysicalDevice physical;
    vkrc::Device device;
    vkrc::Queue queue;
};

Chain make_chain(const std::shared_ptr<ValidationLog>& log) {
    Chain c;
    c.instance = vkrc::Instance::create(vkrc_test::validated_instance_info(log));
    c.physical = vkrc::PhysicalDevice::select(c.instance, vkrc_test::test_device_requirements());
    c.device = vkrc::Device::create(c.physical);
    c.queue = c.device.default_queue();
    return c;
}

// Drops the four handles in every one of the 24 orders: children keep their
// parents alive, so each order must be clean.
TEST(DestructionOrder, EveryOrderIsClean) {
    std::array<int, 4> order{0, 1, 2, 3};
    int runs = 0;
    do {
        auto log = std::make_shared<ValidationLog>();
        Chain c = make_chain(log);
        for (int which : order) {
            switch (which) {
                case 0: c.instance.reset(); break;
                case 1: c.physical.reset(); break;
                case 2: c.device.reset(); break;
                case 3: c.queue = {}; break;
            }
        }
        vkrc_test::expect_no_validation_messages(*log);
        ++runs;
    } while (std::next_permutation(order.begin(), order.end()));
    EXPECT_EQ(runs, 24);
}

// allocator's release() count shows when the device was torn down.
vkrc::Buffer small_buffer(const vkrc::Device& device, const vkrc::SharedAllocator& allocator) {
    return vkrc::Buffer::create(device,
                                {.size = 256, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, .allocator = allocator});
}

// A device outlives its last handle while a child lives, a handle made again
// from a child's device() keeps it too, and it goes with the last of either.
// The layer reports a vkDestroyDevice with live children, and the instance
// dropped last reports a device never destroyed.
TEST(DeviceLifetime, LastChildOrHandleDestroysTheDevice) {
    for (int last_is_handle = 0; last_is_handle < 2; ++last_is_handle) {
        auto log = std::make_shared<ValidationLog>();
        Chain c = make_chain(log);
        const auto allocator = vkrc::make_allocator<vkrc_test::CountingAllocator>();
        vkrc::Buffer first = small_buffer(c.device, allocator);
        c.device.reset();
        c.queue = {};
        vkrc::Device again = first.device();  // a handle again, made from a child
        vkrc::Buffer second = small_buffer(again, allocator);
        EXPECT_EQ(again.use_count(), 1u) << "children hold no handle";
        first.reset();
        if (last_is_handle) {
            second.reset();
            EXPECT_NE(again.vk(), VK_NULL_HANDLE);
            EXPECT_EQ(allocator->releases(), 0) << "torn down while a handle lives";
            again.reset();
        } else {
            again.reset();
            EXPECT_NE(second.device().vk(), VK_NULL_HANDLE);
            EXPECT_EQ(allocator->releases(), 0) << "torn down while a child lives";
            second.reset();
        }
        EXPECT_EQ(allocator->releases(), 1) << "not torn down with the last child or handle";
        c = {};
        vkrc_test::expect_no_validation_messages(*log);
    }
}

TEST_F(VulkanTest, ChildrenKeepParentsAlive) {
    VkDevice raw = device.vk();
    EXPECT_EQ(instance.use_count(), 2u);  // the fixture's handle and the physical device's
    instance.reset();
    physical_device.reset();
    device.reset();
    // The queue alone keeps the device, physical device and instance alive.
    ASSERT_TRUE(queue);
    EXPECT_EQ(queue.device().vk(), raw);
    EXPECT_TRUE(queue.device().instance());
    queue.wait_idle();
    EXPECT_EQ(queue.device().physical_device().instance().physical_devices().size() > 0, true);
}

TEST_F(VulkanTest, CopiesAndMovesShareOneDevice) {
    const auto alone = device.use_count();
    vkrc::Device copy = device;
    EXPECT_EQ(device.use_count(), alone + 1);  // one more reference to the same state
    EXPECT_EQ(copy.state(), device.state());
    vkrc::Device moved = std::move(copy);
    EXPECT_FALSE(copy);                        // NOLINT(bugprone-use-after-move)
    EXPECT_EQ(device.use_count(), alone + 1);  // the reference moved, not copied
    EXPECT_EQ(moved.state(), device.state());
    auto& self = moved;
    moved = self;  // self-assignment keeps the reference
    EXPECT_EQ(device.use_count(), alone + 1);
    EXPECT_EQ(moved.vk(), device.vk());
    moved.reset();
    EXPECT_EQ(device.use_count(), alone);
}

TEST_F(VulkanTest, QueuesAreFoundByFamilyAndIndex) {
    EXPECT_TRUE(device.queue(queue.family_index(), 0) == queue);
    EXPECT_THROW(device.queue(queue.family_index(), 7), vkrc::UsageError);
    EXPECT_THROW(device.queue(999), vkrc::UsageError);
}

TEST_F(VulkanTest, BadQueueRequestsNameTheProblem) {
    vkrc::DeviceCreateInfo info;
    info.queue_requests = {{999, {1.0f}}};
    try {
        vkrc::Device::create(physical_device, info);
        FAIL();
    } catch (const vkrc::UsageError& e) {
        EXPECT_NE(std::string(e.what()).find("queue family 999 does not exist"), std::string::npos) << e.what();
    }
}

// QueueRequest::next reaches VkDeviceQueueCreateInfo: a struct that does not
// extend it, chained on purpose, is reported by the validation layer
// (drivers skip structs they do not expect, as the spec requires).
TEST_F(VulkanTest, RawInteropQueueRequestNextReachesVulkan) {
    const VkFenceCreateInfo foreign{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    auto other = vkrc::Device::create(
        physical_device, {.queue_requests = {{.queue_family_index = queue.family_index(), .next = &foreign}}});
    EXPECT_TRUE(log->take_expected("VUID-VkDeviceQueueCreateInfo-pNext-pNext", 1));
}

TEST_F(VulkanTest, FunctionTableReachesUnwrappedFunctions) {
    ASSERT_NE(device.fn().vkCmdDraw, nullptr);
    ASSERT_NE(device.fn().vkQueueSubmit2, nullptr);
    ASSERT_NE(device.fn().vkCmdBeginRendering, nullptr);
    // A raw call with raw handles, next to the wrappers.
    VkFence fence = VK_NULL_HANDLE;
    VkFenceCreateInfo info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    ASSERT_EQ(device.fn().vkCreateFence(device.vk(), &info, nullptr, &fence), VK_SUCCESS);
    device.fn().vkDestroyFence(device.vk(), fence, nullptr);
}

TEST_F(VulkanTest, AdoptedBorrowedDeviceIsNotDestroyed) {
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    q.queueFamilyIndex = queue.family_index();
    q.queueCount = 1;
    q.pQueuePriorities = &priority;
    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    f12.timelineSemaphore = VK_TRUE;
    VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &f12};
    info.queueCreateInfoCount = 1;
    info.pQueueCreateInfos = &q;
    VkDevice raw = VK_NULL_HANDLE;
    ASSERT_EQ(physical_device.fn().vkCreateDevice(physical_device.vk(), &info, nullptr, &raw), VK_SUCCESS);
    std::vector<vkrc::QueueRequest> queues{{queue.family_index(), {1.0f}}};
    {
        auto borrowed = vkrc::Device::adopt(physical_device, raw, vkrc::Ownership::borrowed, queues);
        borrowed.default_queue().wait_idle();
    }
    // Still valid after the wrapper went; the test destroys it itself.
    auto destroy =
        reinterpret_cast<PFN_vkDestroyDevice>(physical_device.fn().vkGetDeviceProcAddr(raw, "vkDestroyDevice"));
    auto wait =
        reinterpret_cast<PFN_vkDeviceWaitIdle>(physical_device.fn().vkGetDeviceProcAddr(raw, "vkDeviceWaitIdle"));
    EXPECT_EQ(wait(raw), VK_SUCCESS);
    destroy(raw, nullptr);
}

// Blocks the queue on a semaphore the host signals later, so "the GPU may
// still use it" is true for as long as the test wants.
struct BlockedQueue {
    vkrc::Device device;
    VkSemaphore gate = VK_NULL_HANDLE;

    BlockedQueue(const vkrc::Device& d, const vkrc::Queue& q) : device(d) {
        VkSemaphoreTypeCreateInfo type{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
        type.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
        VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, &type};
        vkrc::check(d.fn().vkCreateSemaphore(d.vk(), &info, nullptr, &gate), "vkCreateSemaphore");
        VkSemaphoreSubmitInfo wait{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
        wait.semaphore = gate;
        wait.value = 1;
        wait.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
        VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
        submit.waitSemaphoreInfoCount = 1;
        submit.pWaitSemaphoreInfos = &wait;
        q.submit({&submit, 1});
    }
    void open() const {
        VkSemaphoreSignalInfo signal{VK_STRUCTURE_TYPE_SEMAPHORE_SIGNAL_INFO};
        signal.semaphore = gate;
        signal.value = 1;
        vkrc::check(device.fn().vkSignalSemaphore(device.vk(), &signal), "vkSignalSemaphore");
    }
    // The gate may still be waited on: its destruction goes through the same
    // deferral as any vkrc object's.
    ~BlockedQueue() {
        vkrc::detail::defer_destroy<&vkrc::DeviceFunctions::vkDestroySemaphore>(*device.state(), gate,
                                                                                vkrc::detail::current_serial());
    }
};

int actions_run = 0;
void count_action(vkrc::detail::DeviceState&, std::uint64_t handle, void*) noexcept { actions_run += int(handle); }

TEST_F(VulkanTest, DestructionWaitsForSubmittedWork) {
    actions_run = 0;
    auto& state = *device.state();
    state.destroy_after_gpu({count_action, 1, nullptr}, vkrc::detail::current_serial());
    EXPECT_EQ(actions_run, 1) << "nothing submitted: runs at once";

    BlockedQueue blocked(device, queue);
    state.destroy_after_gpu({count_action, 10, nullptr}, vkrc::detail::current_serial());
    state.destroy_after_gpu({count_action, 100, nullptr}, vkrc::detail::current_serial());
    EXPECT_EQ(actions_run, 1);
    EXPECT_EQ(device.deferred_count(), 2u);
    device.collect_garbage();
    EXPECT_EQ(actions_run, 1) << "the queue is still blocked";

    blocked.open();
    queue.wait_idle();
    EXPECT_EQ(actions_run, 111);
    EXPECT_EQ(device.deferred_count(), 0u);
}

TEST(DeferredDestruction, DeviceTeardownDrainsPendingWork) {
    actions_run = 0;
    auto log = std::make_shared<ValidationLog>();
    {
        Chain c = make_chain(log);
        BlockedQueue blocked(c.device, c.queue);
        c.device.state()->destroy_after_gpu({count_action, 5, nullptr}, vkrc::detail::current_serial());
        EXPECT_EQ(actions_run, 0);
        blocked.open();
        // Every handle goes here, the queue's work possibly still running:
        // teardown waits for idle and runs the action.
    }
    EXPECT_EQ(actions_run, 5);
    vkrc_test::expect_no_validation_messages(*log);
}

TEST_F(VulkanTest, SubmitSignalsTheTimelineOnlyWhenAsked) {
    actions_run = 0;
    auto& q = *queue.state();
    const std::uint64_t signalled = q.timeline.last_signalled();
    VkSubmitInfo2 empty{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    std::array<VkSubmitInfo2, 3> batches{empty, empty, empty};
    const std::uint64_t first = queue.submit(batches);
    EXPECT_EQ(queue.submit({}), first + 1) << "submissions are numbered";
    EXPECT_EQ(q.timeline.last_signalled(), signalled) << "nothing dropped: the application's submits only";

    // A drop while work may be pending asks the next submit for one signal.
    device.state()->destroy_after_gpu({count_action, 1, nullptr}, vkrc::detail::current_serial());
    EXPECT_EQ(device.deferred_count(), 1u);
    const std::uint64_t third = queue.submit(batches);
    EXPECT_EQ(q.timeline.last_signalled(), third);
    queue.submit(batches);
    EXPECT_EQ(q.timeline.last_signalled(), third) << "one signal per request";

    // Waiting on the timeline needs a signalled value: completion_value submits one.
    const std::uint64_t value = queue.completion_value();
    EXPECT_EQ(value, third + 2);
    EXPECT_EQ(queue.completion_value(), value) << "nothing submitted since";
    queue.wait_idle();
    EXPECT_EQ(actions_run, 1);
    std::uint64_t reached = 0;
    ASSERT_EQ(device.fn().vkGetSemaphoreCounterValue(device.vk(), queue.timeline_semaphore(), &reached), VK_SUCCESS);
    EXPECT_EQ(reached, value);
}

TEST_F(VulkanTest, WaitsRunDropsThatNoSubmitSignalled) {
    actions_run = 0;
    VkSubmitInfo2 empty{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    queue.submit(std::span(&empty, 1));
    device.state()->destroy_after_gpu({count_action, 1, nullptr}, vkrc::detail::current_serial());
    device.wait_idle();
    EXPECT_EQ(actions_run, 1) << "Device::wait_idle";
    queue.submit(std::span(&empty, 1));
    device.state()->destroy_after_gpu({count_action, 10, nullptr}, vkrc::detail::current_serial());
    queue.wait_idle();
    EXPECT_EQ(actions_run, 11) << "Queue::wait_idle";
    // A fence signal covers all earlier work on its queue.
    auto fence = vkrc::Fence::create(device);
    queue.submit(std::span(&empty, 1));
    device.state()->destroy_after_gpu({count_action, 100, nullptr}, vkrc::detail::current_serial());
    vkrc::submit(queue, vkrc::SubmitBatch{}, fence);
    EXPECT_EQ(fence.wait(), VK_SUCCESS);
    EXPECT_EQ(actions_run, 111) << "Fence::wait";
    EXPECT_EQ(device.deferred_count(), 0u);
}

TEST_F(VulkanTest, TimelineSignalGoesInItsOwnBatchWhenTheLastIsFull) {
    std::vector<vkrc::Semaphore> semaphores;
    std::vector<VkSemaphoreSubmitInfo> signals;
    for (int i = 0; i < 9; ++i) {
        semaphores.push_back(vkrc::Semaphore::create_timeline(device, 0));
        VkSemaphoreSubmitInfo s{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
        s.semaphore = semaphores.back().vk();
        s.value = 1;
        s.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
        signals.push_back(s);
    }
    for (std::uint32_t count : {8u, 9u}) {
        VkSubmitInfo2 batch{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
        batch.signalSemaphoreInfoCount = count;
        batch.pSignalSemaphoreInfos = signals.data();
        for (auto& s : signals) s.value += 1;
        queue.state()->timeline.request_signal();
        const std::uint64_t number = queue.submit(std::span(&batch, 1));
        EXPECT_EQ(queue.state()->timeline.last_signalled(), number) << count << " signals in the batch";
    }
    queue.wait_idle();
}

#if VKRC_IS_MULTI_THREAD
TEST_F(VulkanTest, SixteenThreadsShareAndDropHandles) {
    std::vector<std::thread> threads;
    for (int t = 0; t < 16; ++t) {
        threads.emplace_back([this, t] {
            for (int i = 0; i < 2000; ++i) {
                vkrc::Device d = device;
                vkrc::Queue q = d.default_queue();
                vkrc::Instance in = q.device().instance();
                vkrc::PhysicalDevice p = d.physical_device();
                if ((i + t) % 500 == 0) q.submit({});
            }
        });
    }
    for (auto& t : threads) t.join();
    queue.wait_idle();
    EXPECT_EQ(device.use_count(), 2u);  // the fixture's device and queue handles
}

// Sixteen threads make and drop buffers (and so their device references,
// counted on per-thread stripes) while the device's handles go one by one:
// each thread drops its own handle halfway and goes on from a buffer it
// keeps, making handles again from it. The device must be destroyed once,
// after its last child (the layer and ASan/TSan watch).
TEST(DeviceLifetime, SixteenThreadsMakeAndDropChildrenWhileTheHandlesGo) {
    auto log = std::make_shared<ValidationLog>();
    Chain c = make_chain(log);
    c.queue = {};
    const auto allocator = vkrc::make_allocator<vkrc_test::CountingAllocator>();
    std::vector<std::thread> threads;
    for (int t = 0; t < 16; ++t) {
        threads.emplace_back([device = c.device, t, &allocator]() mutable {
            vkrc::Buffer kept = small_buffer(device, allocator);
            for (int i = 0; i < 400; ++i) {
                if (i == 200) device.reset();
                const vkrc::Device& from = device ? device : kept.device();
                vkrc::Buffer b = small_buffer(from, allocator);
                if ((i + t) % 7 == 0) {
                    vkrc::Device handle = b.device();  // a handle made from a child
                    b = small_buffer(handle, allocator);
                }
            }
        });
    }
    c.device.reset();  // the threads' copies and buffers keep it
    for (auto& t : threads) t.join();
    EXPECT_EQ(allocator->releases(), 1) << "the device was not torn down once, after its last child";
    c = {};
    vkrc_test::expect_no_validation_messages(*log);
}
#endif

}  // namespace
