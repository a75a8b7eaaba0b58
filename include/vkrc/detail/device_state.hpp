// The machinery behind Device and Queue (not part of the API): queue
// timelines, deferred destruction, open command buffers' recording windows,
// the allocators, and the named operations the other layers call on them
// (DeviceState's, and those below it that start from a Queue). Included by
// vkrc/device.hpp, whose inline accessors need the complete states.
#pragma once

#include "vkrc/device.hpp"

#include "vkrc/detail/object_registry.hpp"

#include <cstdint>
#include <new>

VKRC_BEGIN_NAMESPACE

namespace detail {

// The numbering of one queue's submissions and what is known of their
// completion: vkrc's only GPU-side tracking. Submits are numbered from 1; a
// submit signals the queue's timeline semaphore with its own number only
// when someone asked since the last signal (a dropped object, a pool freeing
// a child, a wait), so frame loops that drop nothing never pay for a signal.
// The note_submitted / note_signalled / next_number / take_signal_request
// calls are made under the queue's mutex; the others from any thread.
class QueueTimeline {
public:
    // The number the next submit gets.
    std::uint64_t next_number() const noexcept { return submitted_.load(__ATOMIC_RELAXED) + 1; }
    // The number of the last submit (0: none yet).
    std::uint64_t last_submitted() const noexcept { return submitted_.load(__ATOMIC_ACQUIRE); }
    // The number of the last submit that signalled the timeline semaphore.
    std::uint64_t last_signalled() const noexcept { return signalled_.load(__ATOMIC_ACQUIRE); }
    // The highest number known to have completed: read from the semaphore,
    // or that of a vkrc-submitted fence seen signalled (a fence signal covers
    // all earlier work on its queue).
    std::uint64_t completed() const noexcept { return completed_.load(__ATOMIC_RELAXED); }

    // Asks the next submit to signal the semaphore.
    void request_signal() noexcept { signal_wanted_.store(true, __ATOMIC_RELAXED); }
    // Whether a signal was asked for since the last one.
    bool signal_requested() const noexcept { return signal_wanted_.load(__ATOMIC_RELAXED); }
    // Clears the request and says whether there was one; taken before
    // submitting, so a request made meanwhile is either covered by this
    // submit's signal or asks the next submit again.
    bool take_signal_request() noexcept { return signal_wanted_.exchange(false, __ATOMIC_RELAXED); }

    // Submit number went in without a signal.
    void note_submitted(std::uint64_t number) noexcept { submitted_.store(number, __ATOMIC_RELEASE); }
    // Submit number went in and signals the semaphore with its number.
    void note_signalled(std::uint64_t number) noexcept {
        submitted_.store(number, __ATOMIC_RELEASE);
        signalled_.store(number, __ATOMIC_RELEASE);
    }
    // Raises completed() to value (several threads may refresh it).
    void note_completed(std::uint64_t value) noexcept {
        std::uint64_t seen = completed_.load(__ATOMIC_RELAXED);
        while (seen < value && !completed_.compare_exchange_weak(seen, value, __ATOMIC_RELAXED)) {}
    }

    // The number whose completion means all work submitted so far has
    // completed. When no signal covers it yet, asks the next submit for one
    // (until then only a vkrc fence of that submit or a later one, or a wait
    // for idle, can show it complete).
    std::uint64_t covering_value() noexcept {
        const std::uint64_t last = last_submitted();
        if (last_signalled() < last) request_signal();
        return last;
    }

private:
    PolicyAtomic<std::uint64_t> submitted_{0};
    PolicyAtomic<std::uint64_t> signalled_{0};
    PolicyAtomic<bool> signal_wanted_{false};
    PolicyAtomic<std::uint64_t> completed_{0};
};

// The vkrc submission a fence was last submitted with (FenceState): its
// queue (null: none, or seen signalled since) and its number there.
struct FencedSubmission {
    QueueState* queue = nullptr;
    std::uint64_t number = 0;
};

class QueueState {
public:
    VkQueue queue = VK_NULL_HANDLE;
    std::uint32_t family_index = 0;
    std::uint32_t index = 0;
    VkSemaphore semaphore = VK_NULL_HANDLE;  // the timeline's, counting in submission numbers
    QueueTimeline timeline;
    mutable Mutex mutex;
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

// The device's queue of deferred actions. Actions queued while the same work
// was pending share one batch; batches run in the order they were queued, so
// an object queued after another (an image after its view) is destroyed after it.
class DeferredDestructor {
public:
    // Runs the action now when no vkrc-submitted work is pending, otherwise once all work submitted before this call has completed.
    void destroy_after_gpu(DeviceState& device, DeferredAction action) noexcept;
    // Runs the queued actions whose work has completed; never blocks on the
    // GPU. Inline: with nothing queued (a steady frame loop) it is one load.
    void collect(DeviceState& device) noexcept {
        if (count_.load(__ATOMIC_RELAXED) != 0) [[unlikely]]
            collect_queued(device);
    }
    // Runs every queued action at once; for teardown, after the GPU is idle or lost.
    void run_all(DeviceState& device) noexcept;
    // The number of queued actions.
    std::size_t size() const noexcept;

private:
    void collect_queued(DeviceState& device) noexcept;
    // Moves the actions whose work has completed to out; may throw bad_alloc.
    void take_ready(DeviceState& device, List<DeferredAction>& out);

    struct Batch {
        List<std::uint64_t> wait_values;  // per queue
        List<DeferredAction> actions;
    };
    mutable Mutex mutex_;
    List<Batch> batches_;
    // Read without the lock by collect() to skip it when nothing is queued.
    PolicyAtomic<std::size_t> count_{0};
};

// One command buffer's recording window, as the device's OpenCommandBuffers
// sees it. end is 0 while closed, UINT64_MAX while recording, and after
// end() the creation counter's value then: the command buffer may refer to
// objects with a lower serial only.
struct RecordingWindow {
    PolicyAtomic<std::uint64_t> end{0};
    const void* pool = nullptr;  // the CommandPoolState, for pool resets
    bool one_time = false;       // a ONE_TIME_SUBMIT primary: closes when submitted
    std::size_t index = 0;       // in the registry
};

// Drops held back while a command buffer that may refer to them is open
// (recording, or executable and not yet submitted for the last time): a drop
// of an object is held while some open window's end exceeds its serial, and
// goes into the deferred queue (so still waits for the GPU) once none does.
// begin/end/close touch the window and one counter; the lock is taken when
// something is held, or to register a command buffer at allocate and free.
class OpenCommandBuffers {
public:
    struct Held {
        DeferredAction action;
        std::uint64_t serial = 0;
    };
    void add(RecordingWindow& window);
    void remove(DeviceState& device, RecordingWindow& window) noexcept;
    void begin(RecordingWindow& window, bool one_time) noexcept {
        window.one_time = one_time;
        if (window.end.exchange(UINT64_MAX) == 0) open_.fetch_add(1);
    }
    void end(RecordingWindow& window) noexcept { window.end.store(current_serial()); }
    void close(DeviceState& device, RecordingWindow& window) noexcept {
        const std::uint64_t end = window.end.exchange(0);
        if (end != 0) open_.fetch_sub(1);
        // Only closing a window at the last computed limit can uncover a held
        // drop: a long hold by a reusable command buffer costs other closes nothing.
        if (held_count_.load() != 0 && end >= covered_.load(__ATOMIC_RELAXED)) release(device);
    }
    // Closes every window of a pool (vkResetCommandPool). A frame loop
    // resets a pool whose ONE_TIME_SUBMIT primaries its submit closed:
    // nothing to scan, no lock (the pool is externally synchronised, so none
    // of its windows opens meanwhile).
    void close_pool(DeviceState& device, const void* pool) noexcept {
        if (open_.load() != 0 || held_count_.load() != 0) close_pool_slow(device, pool);
    }
    // Whether a drop of an object with this serial must wait for a close.
    bool holds(std::uint64_t serial) noexcept;
    // Holds action when holds(serial); false (and nothing done) otherwise.
    bool hold(DeferredAction action, std::uint64_t serial) noexcept;
    // Objects with a serial at or above this are held by no open window.
    std::uint64_t limit() noexcept;
    // Moves the entries no longer held to the deferred queue, in order.
    void release(DeviceState& device) noexcept;
    // collect()'s safety net: release when a hold happened since the last
    // release (stale_ is set only with an entry held, so one load decides).
    void release_if_stale(DeviceState& device) noexcept {
        if (stale_.load(__ATOMIC_RELAXED)) [[unlikely]]
            release(device);
    }
    // Teardown: runs what is still held.
    void run_all(DeviceState& device) noexcept;
    std::size_t held_count() const noexcept { return held_count_.load(__ATOMIC_RELAXED); }

private:
    std::uint64_t limit_locked() const noexcept;
    void close_pool_slow(DeviceState& device, const void* pool) noexcept;
    mutable Mutex mutex_;
    List<RecordingWindow*> windows_;  // every allocated command buffer of the device
    List<Held> held_;
    PolicyAtomic<std::size_t> open_{0};
    PolicyAtomic<std::size_t> held_count_{0};
    PolicyAtomic<bool> stale_{false};
    PolicyAtomic<std::uint64_t> covered_{0};  // limit_locked() at the last hold or release
};

// Every allocator used with the device, kept until teardown so that deferred
// frees can still reach it (memory.cpp).
class AllocatorRegistry {
public:
    // In memory.cpp, where DeviceAllocator is complete (the constructor
    // destroys the list when unwinding).
    AllocatorRegistry();
    ~AllocatorRegistry();
    // The device's default allocator, a PoolAllocator made on first use.
    DeviceAllocator& default_allocator();
    // Takes a reference to allocator, kept until release_all (once per allocator).
    void keep(DeviceAllocator* allocator);
    // Calls each allocator's release() and drops them; teardown, after every deferred free ran.
    void release_all(DeviceState& device) noexcept;

private:
    // Whether allocator is among the first recent_slots kept: read without
    // the lock, so that every allocation does not take it.
    bool kept_recently(const DeviceAllocator* allocator) const noexcept;
    static constexpr std::size_t recent_slots = 32;

    Mutex mutex_;
    List<Ref<DeviceAllocator>> allocators_;  // the default one first, once made
    PolicyAtomic<DeviceAllocator*> default_{nullptr};
    PolicyAtomic<const DeviceAllocator*> recent_[recent_slots];  // written under mutex_, append-only
    PolicyAtomic<std::size_t> recent_count_{0};
};

// What keeps a device alive besides its handles: its children's references
// (DeviceLink) and one share for all its handles together. Under vkrc::mt a
// thread takes and returns references as credits on a stripe of its own,
// and the shared total moves by batches, so that threads making and
// dropping children at once write no shared line (one count written by
// every thread capped Buffer::create + drop at a fraction of one thread's
// rate, bench/contention). When the handles' share goes, every stripe is
// drained and marked dead, and from then on references go to the total,
// so that the drop that takes it to zero is exact.
class ChildCount {
public:
    // Inline under vkrc::st, where each is one plain add: a child's
    // creation and drop pay no call for it.
    void add() noexcept {
        if constexpr (ThreadPolicy::multi_thread) {
            add_striped();
        } else {
            total_.fetch_add(1);
        }
    }
    // True when the total reached zero: the caller destroys the device.
    [[nodiscard]] bool release() noexcept {
        if constexpr (ThreadPolicy::multi_thread) {
            return release_striped();
        } else {
            return total_.fetch_sub(1) == 1;
        }
    }
    // The handles' share, given back by their last one and taken again by a
    // handle made from a child's device() after that.
    void add_handles() noexcept { total_.fetch_add(1, __ATOMIC_RELAXED); }
    [[nodiscard]] bool release_handles() noexcept;

private:
    void add_striped() noexcept;
    bool release_striped() noexcept;
    static constexpr std::size_t stripe_count = ThreadPolicy::multi_thread ? 64 : 1;
    struct alignas(64) Stripe {  // apart in cache: threads on different stripes share no line
        PolicyAtomic<std::int64_t> credits{0};
    };
    Stripe stripes_[stripe_count];
    alignas(64) PolicyAtomic<std::int64_t> total_{1};  // references held + credits on live stripes + the handles' share
};

// The device's machinery, through named operations: the other layers call
// these, never the parts (commands, deferred, allocators) directly.
class DeviceState final : public RefCounted {
    inline static Atomic<std::uint64_t> next_id{0};  // process-wide: atomic under both policies

public:
    ~DeviceState() override;

    // ---- References: handles count in RefCounted, children in ChildCount
    // Hides RefCounted::add_ref (Ref<DeviceState> calls this one): a handle
    // made when none was left takes the handles' share back.
    void add_ref() const noexcept {
        if (add_ref_from_zero()) [[unlikely]]
            children_.add_handles();
    }
    void add_child() noexcept { children_.add(); }
    // May destroy this device: the caller touches it no more.
    void release_child() noexcept {
        if (children_.release()) delete this;
    }

    // ---- Deferred destruction
    // Defers a destruction: see DeferredDestructor::destroy_after_gpu; serial
    // is the dropped object's, which open command buffers may hold back
    // (OpenCommandBuffers).
    void destroy_after_gpu(DeferredAction action, std::uint64_t serial) noexcept {
        if (commands.hold(action, serial)) return;
        deferred.destroy_after_gpu(*this, action);
    }
    // Releases stale holds, then runs the completed deferred actions.
    void collect() noexcept {
        commands.release_if_stale(*this);
        deferred.collect(*this);
    }
    // Objects waiting for the GPU or for an open command buffer.
    std::size_t deferred_count() const noexcept { return deferred.size() + commands.held_count(); }

    // ---- Command buffers' recording windows (OpenCommandBuffers)
    // A command buffer is allocated or adopted (may throw bad_alloc), or freed.
    void register_window(RecordingWindow& window) { commands.add(window); }
    void unregister_window(RecordingWindow& window) noexcept { commands.remove(*this, window); }
    // vkBeginCommandBuffer succeeded.
    void open_window(RecordingWindow& window, bool one_time) noexcept { commands.begin(window, one_time); }
    // Recording is over; called before vkEndCommandBuffer (CommandBuffer::end says why).
    void end_window(RecordingWindow& window) noexcept { commands.end(window); }
    // The command buffer was reset, or its one-time submit went in.
    void close_window(RecordingWindow& window) noexcept { commands.close(*this, window); }
    // Every window of pool closes (vkResetCommandPool).
    void close_pool_windows(const void* pool) noexcept { commands.close_pool(*this, pool); }
    // For pools that free their children themselves (PoolFreeList): whether
    // an open window may refer to an object of this serial, and the serial
    // at or above which none does.
    bool held_back(std::uint64_t serial) noexcept { return commands.holds(serial); }
    std::uint64_t hold_limit() noexcept { return commands.limit(); }

    // ---- Allocators
    // The device's default allocator, a PoolAllocator made on first use.
    DeviceAllocator& default_allocator() { return allocators.default_allocator(); }
    // Keeps allocator until teardown, so that deferred frees still reach it.
    void keep_allocator(DeviceAllocator* allocator) { allocators.keep(allocator); }

    // ---- Results and device loss
    // Marks the device lost: the GPU will touch nothing any more, so every
    // queued action may run.
    void mark_lost() noexcept { lost.store(true, __ATOMIC_RELAXED); }
    // Marks the device lost when r says so; returns r.
    VkResult note_result(VkResult r) noexcept {
        if (r == VK_ERROR_DEVICE_LOST) mark_lost();
        return r;
    }
    // Marks the device lost when r says so, then check(r, call).
    VkResult check_result(VkResult r, const char* call) { return check(note_result(r), call); }
    // After a call that may have run or waited for GPU work: marks the device
    // lost when r says so, runs the completed deferred actions, then check(r, call).
    VkResult finish_call(VkResult r, const char* call) {
        // Success tested once: the frame loop's path does not test r again after collecting.
        if (r == VK_SUCCESS) [[likely]] {
            collect();
            return VK_SUCCESS;
        }
        return finish_failed_call(r, call);
    }
    // finish_call's other results, out of line.
    VkResult finish_failed_call(VkResult r, const char* call);

    // ---- Queues' timelines
    // Queue::submit: submits under the queue's lock, signalling the queue's
    // timeline when asked to, and returns the submission's number; fenced,
    // if given, receives the queue and number (vkrc::submit's fence).
    // Inline: vkrc::submit's frame loop reaches vkQueueSubmit2 without
    // another call. The submission is noted before the driver call, so that
    // nothing of it is kept in a register across the call: other threads
    // may see its number a moment early, which only makes what waits for
    // it wait for this submission too. When the call fails, fenced is
    // cleared and the number stays used (a wait for it is met by any later
    // signal; submit_signalling, the rare path, gives it back itself).
    [[gnu::always_inline]] std::uint64_t submit(QueueState& queue, Span<const VkSubmitInfo2> submits, VkFence fence,
                                                FencedSubmission* fenced = nullptr) {
        VkResult r;
        std::uint64_t number;
        {
            LockGuard lock(queue.mutex);
            number = queue.timeline.next_number();
            if (fenced) *fenced = {&queue, number};
            if (!queue.timeline.signal_requested()) [[likely]] {
                queue.timeline.note_submitted(number);
                r = fn.vkQueueSubmit2(queue.queue, static_cast<std::uint32_t>(submits.size()), submits.data(), fence);
            } else {
                r = submit_signalling(queue, submits, fence, number);
            }
        }
        if (r < 0) [[unlikely]]
            fail_submit(r, fenced);
        collect();
        return number;
    }
    // submit's failure r: clears fenced (if any), marks the device lost when
    // r says so, runs the completed deferred actions and throws Error.
    [[noreturn]] void fail_submit(VkResult r, FencedSubmission* fenced);
    // Under the queue's lock: submits with the queue's timeline signal of
    // number added (into the last batch when its signals fit on the stack,
    // else into one more batch, which submission order still places after all
    // the work before it).
    VkResult submit_signalling(QueueState& queue, Span<const VkSubmitInfo2> submits, VkFence fence,
                               std::uint64_t number) noexcept;
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
    // wait_for_submission, throwing Error (DeviceLostError) on failure.
    void await(QueueState& queue, std::uint64_t number);
    // Reads the queue's timeline semaphore and returns the highest number
    // known complete; throws Error (DeviceLostError) when the read fails.
    std::uint64_t read_completed(QueueState& queue);

    // For objects a pool owns (command buffers, descriptor sets), which must
    // be freed under their pool's lock rather than by a DeferredAction: the
    // covering values of every queue (out is resized to the queue count), and
    // whether the GPU has completed the work they stand for.
    void submitted_snapshot(List<std::uint64_t>& out);
    bool reached(Span<const std::uint64_t> snapshot) noexcept;
    // Whether that work is known complete without asking the GPU: no call.
    bool known_reached(Span<const std::uint64_t> snapshot) const noexcept {
        for (std::size_t i = 0; i < snapshot.size() && i < queues.size(); ++i) {
            if (queues[i].timeline.completed() < snapshot[i]) return false;
        }
        return true;
    }
    // Reads the queues' timelines; true when everything submitted has completed.
    bool idle_now() noexcept;

    VkDevice device = VK_NULL_HANDLE;
    // Unique in the process (an address may be reused by a later device):
    // keys what a thread caches about this device (resource.cpp's format queries).
    const std::uint64_t id = next_id.fetch_add(1, __ATOMIC_RELAXED) + 1;
    DeviceFunctions fn;
    // Loaded by the first Device::ext_fn() (src/extension_functions.cpp).
    PolicyAtomic<DeviceExtensionFunctions*> ext_fn{nullptr};
    PhysicalDevice physical_device;
    Ownership ownership = Ownership::owned;
    List<Text> enabled_extensions;
    // As enabled at creation (adopted: as the physical device offers them), for create-time checks.
    DeviceFeatures enabled_features;
    List<QueueState> queues;                 // made once, never grows: Queue handles point into it
    std::size_t role_queues[3] = {0, 0, 0};  // by QueueRole: an index into queues
    PolicyAtomic<bool> lost{false};
    // Raw handle -> state of what descriptors point to (descriptor writes of raw handles).
    ObjectRegistry objects;

private:
    friend class OpenCommandBuffers;  // moves released drops into deferred
    // The last handle went: the handles' share of children_ goes.
    void on_last_release() noexcept override {
        if (children_.release_handles()) delete this;
    }
    // Reads one queue's timeline into its completed cache.
    VkResult refresh(QueueState& queue) noexcept;

    OpenCommandBuffers commands;
    DeferredDestructor deferred;
    AllocatorRegistry allocators;
    mutable ChildCount children_;
};

// The timeline operations from a Queue handle, for the layers above the
// device (stream, swapchain, presenters).
// The highest submission number of queue known complete (no call).
inline std::uint64_t completed(const Queue& queue) noexcept { return queue.state()->timeline.completed(); }
// The number of queue's last submission (0: none).
inline std::uint64_t last_submitted(const Queue& queue) noexcept { return queue.state()->timeline.last_submitted(); }
// A number whose completion means all work submitted so far on queue has
// completed; asks the next submit to signal it when no signal does.
inline std::uint64_t covering_value(const Queue& queue) noexcept { return queue.state()->timeline.covering_value(); }
// Asks queue's next submit to signal its timeline.
inline void request_signal(const Queue& queue) noexcept { queue.state()->timeline.request_signal(); }
// DeviceState::read_completed and DeviceState::await of queue.
inline std::uint64_t read_completed(const Queue& queue) {
    return queue.device().state()->read_completed(*queue.state());
}
inline void await(const Queue& queue, std::uint64_t number) { queue.device().state()->await(*queue.state(), number); }

// Queue::submit that always signals the queue's timeline with the
// submission's number, which it returns: a value to wait on at once, for
// tickets (stream.cpp). Throws DeviceLostError on device loss.
std::uint64_t submit_signalled(const Queue& queue, Span<const VkSubmitInfo2> submits);

// Whether a handle type is a pointer (std::is_pointer_v without <type_traits>,
// which would be most of what a translation unit including vkrc parses).
template <class T>
inline constexpr bool is_pointer = false;
template <class T>
inline constexpr bool is_pointer<T*> = true;

// Converts any Vulkan handle to the word stored in a DeferredAction.
// (Pointers on 64-bit targets; non-dispatchable handles are 64-bit integers elsewhere.)
template <class VkHandle>
std::uint64_t handle_bits(VkHandle handle) noexcept {
    if constexpr (is_pointer<VkHandle>) {
        return reinterpret_cast<std::uintptr_t>(handle);
    } else {
        return static_cast<std::uint64_t>(handle);
    }
}
template <class VkHandle>
VkHandle handle_from_bits(std::uint64_t bits) noexcept {
    if constexpr (is_pointer<VkHandle>) {
        return reinterpret_cast<VkHandle>(static_cast<std::uintptr_t>(bits));
    } else {
        return static_cast<VkHandle>(bits);
    }
}

// Queues vkDestroyX(device, handle, nullptr) to run after the GPU is done.
// Usage: defer_destroy<&DeviceFunctions::vkDestroyBuffer>(device, buffer, serial());
// serial: the dropped state's serial().
template <auto DestroyMember, class VkHandle>
void defer_destroy(DeviceState& device, VkHandle handle, std::uint64_t serial) noexcept {
    if (handle == VK_NULL_HANDLE) return;
    device.destroy_after_gpu({[](DeviceState& d, std::uint64_t bits, void*) noexcept {
                                  (d.fn.*DestroyMember)(d.device, handle_from_bits<VkHandle>(bits), nullptr);
                              },
                              handle_bits(handle), nullptr},
                             serial);
}

// Queues destroy (a vkDestroy* member of DeviceFunctions) of the handle of
// state, an object of device, for after the GPU when vkrc owns it; nothing
// for a borrowed handle or a failed creation.
template <auto destroy, class VkHandle>
void destroy_owned(const VulkanObjectState<VkHandle>& state, const Device& device) noexcept {
    if (device && state.owns_handle()) defer_destroy<destroy>(*device.state(), state.handle, state.serial());
}

// A child's reference to its device, which keeps it alive (ChildCount) and
// reads as a Device: a copy of that Device is a handle of its own.
class DeviceLink {
public:
    // Out of line (device.cpp): made and dropped with objects, never per
    // command, and every child state's destructor would parse them.
    DeviceLink() noexcept {}
    explicit DeviceLink(const Device& device) noexcept;
    DeviceLink(DeviceLink&& other) noexcept;
    DeviceLink(const DeviceLink&) = delete;
    DeviceLink& operator=(const DeviceLink&) = delete;
    DeviceLink& operator=(const Device& device) noexcept;
    ~DeviceLink();
    explicit operator bool() const noexcept { return state() != nullptr; }
    DeviceState* state() const noexcept { return view_.device.state(); }
    operator const Device&() const noexcept { return view_.device; }
    // Device's accessors, which the children's code reaches through it.
    VkDevice vk() const VKRC_UNCHECKED_NOEXCEPT { return view_.device.vk(); }
    const DeviceFunctions& fn() const VKRC_UNCHECKED_NOEXCEPT { return view_.device.fn(); }
    const PhysicalDevice& physical_device() const VKRC_UNCHECKED_NOEXCEPT { return view_.device.physical_device(); }

private:
    // A Device that counts nothing: made over the state without a
    // reference and never destroyed (its union's destructor does nothing).
    union View {
        explicit View(DeviceState* s = nullptr) noexcept : device(Device::view_of(s)) {}
        ~View() {}
        DeviceState* take() noexcept {
            DeviceState* s = device.state();
            set(nullptr);
            return s;
        }
        void set(DeviceState* s) noexcept { new (&device) Device(Device::view_of(s)); }
        Device device;
    } view_;
};

// The state of most objects made from a Device: the device, kept alive.
template <class VkHandle>
class DeviceChildState : public VulkanObjectState<VkHandle> {
public:
    DeviceLink device;
};

}  // namespace detail

// Device's and Queue's accessors, inline for the hot path: here, where the states are complete.
inline VkDevice Device::vk() const VKRC_UNCHECKED_NOEXCEPT { return live("vkrc::Device::vk").device; }
inline const DeviceFunctions& Device::fn() const VKRC_UNCHECKED_NOEXCEPT { return live("vkrc::Device::fn").fn; }
inline const PhysicalDevice& Device::physical_device() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::Device::physical_device").physical_device;
}
inline const Instance& Device::instance() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::Device::instance").physical_device.instance();
}

inline VkQueue Queue::vk() const noexcept { return queue_->queue; }
inline std::uint32_t Queue::family_index() const noexcept { return queue_->family_index; }
inline std::uint32_t Queue::index() const noexcept { return queue_->index; }
inline VkSemaphore Queue::timeline_semaphore() const noexcept { return queue_->semaphore; }
inline Mutex& Queue::mutex() const noexcept { return queue_->mutex; }

VKRC_END_NAMESPACE
