// State blocks behind Device and Queue, and the deferred-destruction queue.
// Included by device.hpp.
#pragma once

#include "vkrc/device.hpp"

#include <deque>

VKRC_BEGIN_NAMESPACE
class DeviceAllocator;
namespace detail {

struct QueueState {
    VkQueue queue = VK_NULL_HANDLE;
    std::uint32_t family_index = 0;
    std::uint32_t index = 0;
    // vkrc's only GPU-side tracking. Submits are numbered; a submit signals
    // this semaphore with its own number only when someone asked since the
    // last signal (signal_wanted): a dropped object, a pool freeing a child,
    // a wait. Frame loops that drop nothing never pay for a signal.
    VkSemaphore timeline = VK_NULL_HANDLE;
    // The number of the last submit, and of the last one that signalled.
    // Written under mutex.
    detail::Atomic<std::uint64_t> submitted{0};
    detail::Atomic<std::uint64_t> signalled{0};
    detail::Atomic<bool> signal_wanted{false};
    // The highest submit number known to have completed: read from the
    // timeline, or that of a vkrc-submitted fence seen signalled (a fence
    // signal covers all earlier work on its queue).
    detail::Atomic<std::uint64_t> completed{0};
    mutable Mutex mutex;

    // The number whose completion means all work submitted so far has
    // completed. When no signal covers it yet, asks the next submit for one
    // (until then only a vkrc fence of that submit or a later one, or a wait
    // for idle, can show it complete).
    std::uint64_t covering_value() noexcept {
        const std::uint64_t last = submitted.load(__ATOMIC_ACQUIRE);
        if (signalled.load(__ATOMIC_ACQUIRE) < last) signal_wanted.store(true, __ATOMIC_RELAXED);
        return last;
    }
    // Raises the completed cache to value (several threads may refresh it).
    void note_completed(std::uint64_t value) noexcept {
        std::uint64_t seen = completed.load(__ATOMIC_RELAXED);
        while (seen < value && !completed.compare_exchange_weak(seen, value, __ATOMIC_RELAXED)) {}
    }
};

// Work to run once the GPU is done with an object: destroying its Vulkan
// handle, or returning its memory to an allocator. A plain function pointer
// and two words, so that queued actions hold no references and a Device with
// pending actions is still torn down when its last handle goes.
struct DeferredAction {
    void (*run)(DeviceState& device, std::uint64_t handle, void* context) noexcept = nullptr;
    std::uint64_t handle = 0;
    void* context = nullptr;
};

class DeviceState final : public RefCounted {
public:
    ~DeviceState() override;

    // Runs the action now when no vkrc-submitted work is pending on any
    // queue, otherwise once all work submitted before this call has completed.
    // Actions run in the order they were queued, so an object queued after
    // another (an image after its view) is destroyed after it.
    void destroy_after_gpu(DeferredAction action) noexcept;
    // Runs the queued actions whose work has completed; never blocks on the GPU.
    void collect() noexcept;
    // Marks the device lost: the GPU will touch nothing any more, so every
    // queued action may run.
    void mark_lost() noexcept { lost.store(true, __ATOMIC_RELAXED); }
    std::size_t deferred_count() const noexcept;
    // Under the queue's lock: when submits since the last timeline signal
    // carried none, submits an empty batch that signals. value receives a
    // timeline value, signalled or on its way, that covers all work submitted
    // so far.
    VkResult signal_submitted_work(QueueState& queue, std::uint64_t& value) noexcept;
    // Waits until the queue's submission number has completed (at once when
    // a fence or the timeline has already shown it), signalling the timeline
    // first when no submit has; failed_call, if given, receives the name of
    // the call that failed.
    VkResult wait_for_submission(QueueState& queue, std::uint64_t number, const char** failed_call = nullptr) noexcept;

    // For objects a pool owns (command buffers, descriptor sets), which must
    // be freed under their pool's lock rather than by a DeferredAction: the
    // covering values of every queue (out is resized to the queue count), and
    // whether the GPU has completed the work they stand for.
    void submitted_snapshot(std::vector<std::uint64_t>& out);
    bool reached(std::span<const std::uint64_t> snapshot) noexcept;

    VkDevice device = VK_NULL_HANDLE;
    DeviceFunctions fn;
    PhysicalDevice physical_device;
    Ownership ownership = Ownership::owned;
    std::vector<Text> enabled_extensions;
    std::deque<QueueState> queues;  // a deque: Queue handles point into it
    detail::Atomic<bool> lost{false};

    // Memory (memory.cpp). Every allocator used with the device is kept until
    // teardown, so that deferred frees can still reach it; teardown runs them
    // all, then calls each allocator's release() before destroying the device.
    DeviceAllocator& default_allocator();  // a PoolAllocator, made on first use
    void keep_allocator(const Ref<DeviceAllocator>& allocator);
    void release_allocators() noexcept;

private:
    // Reads the queues' timelines; true when everything submitted has completed.
    bool idle_now() noexcept;
    // Reads one queue's timeline into its completed cache; false on failure.
    bool refresh(QueueState& queue) noexcept;
    // Moves the actions whose work has completed to out; may throw bad_alloc.
    void take_ready(std::vector<DeferredAction>& out);

    // Actions queued while the same work was pending share one batch.
    struct Batch {
        std::vector<std::uint64_t> wait_values;  // per queue
        std::vector<DeferredAction> actions;
    };
    mutable Mutex deferred_mutex_;
    std::deque<Batch> deferred_;
    // Read without the lock by collect() to skip it when nothing is queued.
    detail::Atomic<std::size_t> deferred_actions_{0};
    Mutex allocators_mutex_;
    std::vector<Ref<DeviceAllocator>> allocators_;  // the default one first, once made
    DeviceAllocator* default_allocator_ = nullptr;
};

// Converts any Vulkan handle to the word stored in a DeferredAction.
template <class VkHandle>
std::uint64_t handle_bits(VkHandle handle) noexcept {
    return (std::uint64_t)(handle);
}
template <class VkHandle>
VkHandle handle_from_bits(std::uint64_t bits) noexcept {
    return (VkHandle)(bits);
}

// Queues vkDestroyX(device, handle, nullptr) to run after the GPU is done.
// Usage: defer_destroy<&DeviceFunctions::vkDestroyBuffer>(device, buffer);
template <auto DestroyMember, class VkHandle>
void defer_destroy(DeviceState& device, VkHandle handle) noexcept {
    if (handle == VK_NULL_HANDLE) return;
    device.destroy_after_gpu({[](DeviceState& d, std::uint64_t bits, void*) noexcept {
                                  (d.fn.*DestroyMember)(d.device, handle_from_bits<VkHandle>(bits), nullptr);
                              },
                              handle_bits(handle), nullptr});
}

}  // namespace detail

inline VkDevice Device::vk() const noexcept { return state_->device; }
inline const DeviceFunctions& Device::fn() const noexcept { return state_->fn; }
inline const PhysicalDevice& Device::physical_device() const noexcept { return state_->physical_device; }
inline const Instance& Device::instance() const noexcept { return state_->physical_device.instance(); }

inline VkQueue Queue::vk() const noexcept { return queue_->queue; }
inline std::uint32_t Queue::family_index() const noexcept { return queue_->family_index; }
inline std::uint32_t Queue::index() const noexcept { return queue_->index; }
inline VkSemaphore Queue::timeline_semaphore() const noexcept { return queue_->timeline; }
inline Mutex& Queue::mutex() const noexcept { return queue_->mutex; }

VKRC_END_NAMESPACE
