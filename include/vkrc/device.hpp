// Logical device, queues, and deferred destruction of device children.
#pragma once

#include "vkrc/instance.hpp"

#include <span>

VKRC_BEGIN_NAMESPACE

namespace detail {
class DeviceState;
struct QueueState;
}  // namespace detail

// Queues wanted from one family (VkDeviceQueueCreateInfo).
struct QueueRequest {
    std::uint32_t queue_family_index = 0;
    std::vector<float> queue_priorities = {1.0f};
};

// Mirrors VkDeviceCreateInfo. vkrc always turns on timelineSemaphore,
// synchronization2, dynamicRendering and maintenance4 (it is built on them, and
// SPIR-V compiled for Vulkan 1.3 needs maintenance4); set any other
// feature in the structs below. vkrc fills their sType and pNext.
struct DeviceCreateInfo {
    // Empty: one queue from the first family with graphics and compute.
    std::vector<QueueRequest> queue_requests;
    std::vector<const char*> enabled_extension_names;
    VkPhysicalDeviceFeatures enabled_features{};
    VkPhysicalDeviceVulkan11Features vulkan11_features{};
    VkPhysicalDeviceVulkan12Features vulkan12_features{};
    VkPhysicalDeviceVulkan13Features vulkan13_features{};
    // Enable VK_EXT_memory_budget when the device has it (for allocator statistics).
    bool enable_memory_budget = true;
    // Chained after vkrc's feature structs (must not repeat them).
    const void* next = nullptr;
};

class Queue;

// A logical device; keeps its PhysicalDevice (and so its Instance) alive.
class Device : public Handle<detail::DeviceState> {
public:
    Device() noexcept = default;
    static Device create(const PhysicalDevice& physical_device, const DeviceCreateInfo& info);
    // The defaults: a separate overload so that a caller's translation unit
    // does not build and destroy a default create-info (bench/header_cost).
    static Device create(const PhysicalDevice& physical_device);
    // Wraps a device made elsewhere; queues lists what it was created with.
    // Its functions are loaded with vkGetDeviceProcAddr either way.
    static Device adopt(const PhysicalDevice& physical_device, VkDevice device, Ownership ownership,
                        std::span<const QueueRequest> queues, std::span<const char* const> enabled_extensions = {});

    VkDevice vk() const noexcept;
    const DeviceFunctions& fn() const noexcept;
    const PhysicalDevice& physical_device() const noexcept;
    const Instance& instance() const noexcept;
    bool extension_enabled(const char* name) const noexcept;

    // The index-th queue of a family requested at creation; throws UsageError otherwise.
    Queue queue(std::uint32_t family_index, std::uint32_t index = 0) const;
    // The first queue created (the default request's queue).
    Queue default_queue() const;

    // vkDeviceWaitIdle, then runs every deferred destruction.
    void wait_idle() const;
    // Runs the deferred destructions whose GPU work has completed. vkrc calls
    // this on every submit and wait; applications need not.
    void collect_garbage() const noexcept;
    // Number of Vulkan objects and allocations waiting for the GPU.
    std::size_t deferred_count() const noexcept;
    // True once any call reported VK_ERROR_DEVICE_LOST.
    bool lost() const noexcept;

private:
    using Handle::Handle;
    friend class Queue;
};

// A queue; keeps its Device alive. Submission and presentation take the
// queue's lock under the multi-thread policy (Vulkan requires external
// synchronisation of queues); nothing else does.
class Queue {
public:
    Queue() noexcept = default;

    VkQueue vk() const noexcept;
    std::uint32_t family_index() const noexcept;
    std::uint32_t index() const noexcept;
    const Device& device() const noexcept { return device_; }
    explicit operator bool() const noexcept { return queue_ != nullptr; }

    // vkQueueSubmit2 with the batches as given. When vkrc needs to know when
    // the work submitted so far completes (an object was dropped, a pool
    // freed a command buffer, a presenter waits), the submit also signals
    // the queue's timeline semaphore, once; otherwise it is the application's
    // submit and nothing more, so a frame loop that drops nothing pays no
    // GPU-lifetime tracking at all. No heap allocation. Returns the
    // submission's number on this queue (they count up from 1).
    // Throws DeviceLostError on device loss.
    std::uint64_t submit(std::span<const VkSubmitInfo2> submits, VkFence fence = VK_NULL_HANDLE) const;
    // vkQueueWaitIdle, then runs deferred destructions.
    void wait_idle() const;

    // A value of timeline_semaphore() that is reached once all work
    // submitted so far through vkrc has completed (the timeline counts in
    // submission numbers). When the last submits carried no signal, submits
    // an empty batch that signals, so the value can always be waited on.
    // Takes the queue's lock: not for the hot path.
    std::uint64_t completion_value() const;
    VkSemaphore timeline_semaphore() const noexcept;
    // The queue's lock, for applications that call vkQueue* themselves from several threads.
    Mutex& mutex() const noexcept;

    friend bool operator==(const Queue& a, const Queue& b) noexcept { return a.queue_ == b.queue_; }
    detail::QueueState* state() const noexcept { return queue_; }

private:
    friend class Device;
    Queue(Device device, detail::QueueState* queue) noexcept : device_(std::move(device)), queue_(queue) {}
    Device device_;
    detail::QueueState* queue_ = nullptr;  // owned by the device
};

VKRC_END_NAMESPACE

#include "vkrc/detail/device_state.hpp"
