// Device loss: VK_ERROR_DEVICE_LOST from a submit, a fence wait or a
// semaphore wait raises DeviceLostError and marks the device lost; then every
// remaining handle can be dropped in any order without hanging (no wait for
// a timeline that will never advance: every wait path reports the loss) and
// without validation messages. lavapipe is not really lost, so the loss is
// simulated by the fault injector (faults::lose_device): the work submitted
// so far completes, and from then on every call that reports loss does.
#include "support/fault_injection.hpp"
#include "support/vk_test.hpp"
#include "support/watchdog.hpp"

#include <algorithm>
#include <array>
#include <functional>
#include <memory>
#include <random>
#include <span>
#include <vector>

namespace {

namespace faults = vkrc_test::faults;

using vkrc_test::Watchdog;

// Objects of every kind, some with work pending on the GPU, some dropped
// (deferred) and some returned to their pool's pending list at the loss.
struct World {
    std::shared_ptr<vkrc_test::ValidationLog> log = std::make_shared<vkrc_test::ValidationLog>();
    vkrc::Instance instance;
    vkrc::PhysicalDevice physical_device;
    vkrc::Device device;
    vkrc::Queue queue;
    vkrc::Buffer buffer, mapped;
    vkrc::Image image;
    vkrc::ImageView view;
    vkrc::Sampler sampler;
    vkrc::CommandPool command_pool;
    vkrc::CommandBuffer cmd, cmd2;
    vkrc::Fence fence, idle_fence;
    vkrc::Semaphore timeline, binary;
    vkrc::Event event;
    vkrc::QueryPool queries;
    vkrc::DescriptorSetLayout set_layout;
    vkrc::DescriptorPool descriptor_pool;
    vkrc::DescriptorSet set;

    World() {
        faults::arm(0, VK_SUCCESS);
        auto info = vkrc_test::validated_instance_info(log);
        info.get_instance_proc_addr = faults::get_instance_proc_addr();
        instance = vkrc::Instance::create(info);
        physical_device = vkrc::PhysicalDevice::select(instance, vkrc_test::test_device_requirements());
        device = vkrc::Device::create(physical_device);
        queue = device.default_queue();
        buffer = vkrc::Buffer::create(
            device, {.size = 1 << 16, .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT});
        mapped = vkrc::Buffer::create(
            device,
            {.size = 256, .usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT, .memory = {.usage = vkrc::MemoryUsage::upload}});
        image = vkrc::Image::create(
            device, {.format = VK_FORMAT_R8G8B8A8_UNORM, .extent = {16, 16, 1}, .usage = VK_IMAGE_USAGE_SAMPLED_BIT});
        view = vkrc::ImageView::create(image);
        sampler = vkrc::Sampler::create(device);
        command_pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
        cmd = command_pool.allocate();
        cmd2 = command_pool.allocate();
        fence = vkrc::Fence::create(device);
        idle_fence = vkrc::Fence::create(device);
        timeline = vkrc::Semaphore::create_timeline(device);
        binary = vkrc::Semaphore::create_binary(device);
        event = vkrc::Event::create(device);
        queries = vkrc::QueryPool::create(device, {.query_count = 2});
        set_layout = vkrc::DescriptorSetLayout::create(
            device, {.bindings = {{.binding = 0, .descriptor_type = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER}}});
        descriptor_pool = vkrc::DescriptorPool::create(
            device, {.max_sets = 2, .pool_sizes = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 2}}});
        set = descriptor_pool.allocate(set_layout);
        set.write_buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, buffer);

        // Work submitted before the loss (the simulated loss lets it finish).
        for (const auto& c : {cmd, cmd2}) {
            c.begin();
            c.fill_buffer(buffer, 0, VK_WHOLE_SIZE, 7);
            c.end();
        }
        const vkrc::CommandBuffer first[] = {cmd};
        vkrc::submit(queue, {.command_buffers = first}, fence);
        // Dropped while pending: onto the pool's pending-free list, and a
        // deferred destruction waiting for the queue timeline.
        const vkrc::CommandBuffer second[] = {cmd2};
        vkrc::submit(queue, {.command_buffers = second});
        cmd2.reset();
        vkrc::Buffer(vkrc::Buffer::create(device, {.size = 64, .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT})).reset();
    }

    // Every handle, each with a way to drop it.
    std::vector<std::function<void()>> droppers() {
        return {[this] { instance.reset(); },
                [this] { physical_device.reset(); },
                [this] { device.reset(); },
                [this] { queue = {}; },
                [this] { buffer.reset(); },
                [this] { mapped.reset(); },
                [this] { image.reset(); },
                [this] { view.reset(); },
                [this] { sampler.reset(); },
                [this] { command_pool.reset(); },
                [this] { cmd.reset(); },
                [this] { fence.reset(); },
                [this] { idle_fence.reset(); },
                [this] { timeline.reset(); },
                [this] { binary.reset(); },
                [this] { event.reset(); },
                [this] { queries.reset(); },
                [this] { set_layout.reset(); },
                [this] { descriptor_pool.reset(); },
                [this] { set.reset(); }};
    }
};

enum class Observer { submit, fence_wait, semaphore_wait };

// The first call after the loss, which must raise DeviceLostError.
void observe_loss(World& w, Observer how) {
    switch (how) {
        case Observer::submit: {
            w.cmd2 = w.command_pool.allocate();
            w.cmd2.begin();
            w.cmd2.end();
            const vkrc::CommandBuffer c[] = {w.cmd2};
            vkrc::submit(w.queue, {.command_buffers = c}, w.idle_fence);
            break;
        }
        case Observer::fence_wait: w.fence.wait(); break;
        case Observer::semaphore_wait: w.timeline.wait(5); break;
    }
}

void lose_and_drop(Observer how, unsigned seed) {
    Watchdog watchdog("losing the device and dropping every handle");
    World w;
    faults::lose_device();
    try {
        observe_loss(w, how);
        ADD_FAILURE() << "no DeviceLostError";
    } catch (const vkrc::DeviceLostError& e) {
        EXPECT_TRUE(faults::fired()) << e.what();
    }
    EXPECT_TRUE(w.device.lost());
    w.cmd2.reset();  // the submit observer's, which never reached the GPU

    // Every wait path reports the loss instead of waiting for ever.
    EXPECT_THROW(w.fence.wait(), vkrc::DeviceLostError);
    EXPECT_THROW(w.idle_fence.wait(), vkrc::DeviceLostError);
    EXPECT_THROW(w.timeline.wait(1000), vkrc::DeviceLostError);
    EXPECT_THROW(w.queue.wait_idle(), vkrc::DeviceLostError);
    EXPECT_THROW(w.device.wait_idle(), vkrc::DeviceLostError);
    EXPECT_THROW(vkrc::upload_buffer(w.queue, w.buffer, 0, std::as_bytes(std::span("data", 4))), vkrc::DeviceLostError);
    // The pools' pending lists count as done.
    auto another = w.command_pool.allocate();
    EXPECT_EQ(w.command_pool.pending_free_count(), 0u);
    another.reset();
    EXPECT_EQ(w.device.deferred_count(), 0u) << "deferred destructions wait for a lost device";

    auto drops = w.droppers();
    std::vector<std::size_t> order(drops.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    if (seed == 1) std::reverse(order.begin(), order.end());
    if (seed > 1) std::shuffle(order.begin(), order.end(), std::mt19937(seed));
    auto log = w.log;
    for (auto i : order) drops[i]();
    faults::arm(0, VK_SUCCESS);
    auto messages = log->take();
    EXPECT_TRUE(messages.empty()) << "drop order seed " << seed << ": " << messages.size()
                                  << " validation message(s), first: " << messages.front();
}

TEST(DeviceLoss, SubmitReportsLossAndEveryHandleDropsInAnyOrder) {
    for (unsigned seed = 0; seed < 5; ++seed) lose_and_drop(Observer::submit, seed);
}

TEST(DeviceLoss, FenceWaitReportsLossAndEveryHandleDropsInAnyOrder) {
    for (unsigned seed = 0; seed < 5; ++seed) lose_and_drop(Observer::fence_wait, seed);
}

TEST(DeviceLoss, SemaphoreWaitReportsLossAndEveryHandleDropsInAnyOrder) {
    for (unsigned seed = 0; seed < 5; ++seed) lose_and_drop(Observer::semaphore_wait, seed);
}

}  // namespace
