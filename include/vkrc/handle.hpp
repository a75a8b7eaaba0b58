// The handle model: intrusive reference counts under a thread policy.
//
// Every vkrc object is one heap block (a "state") that holds the Vulkan
// handle, the references to its parents and the count. User-facing wrappers
// (Instance, Device, Buffer, ...) are Handle<State>: one pointer, copy shares,
// move transfers, the last owner releases the state.
#pragma once

#include "vkrc/config.hpp"
#include "vkrc/detail/moves.hpp"

#include <vulkan/vulkan_core.h>

#include <cstdint>

VKRC_BEGIN_NAMESPACE

namespace detail {

// A word accessed atomically, with the subset of std::atomic's interface vkrc
// uses (memory orders are std::memory_order values, or __ATOMIC_* constants).
// GCC/Clang builtins instead of <atomic>: with C++20, libstdc++'s <atomic>
// brings in the atomic-wait machinery, <system_error> and <string>, which
// every translation unit that includes vkrc would parse (bench/header_cost).
template <class T>
class Atomic {
public:
    constexpr Atomic(T value = T{}) noexcept : value_(value) {}
    Atomic(const Atomic&) = delete;
    Atomic& operator=(const Atomic&) = delete;

    template <class Order = int>
    T load(Order order = Order(__ATOMIC_SEQ_CST)) const noexcept {
        return __atomic_load_n(&value_, static_cast<int>(order));
    }
    template <class Order = int>
    void store(T value, Order order = Order(__ATOMIC_SEQ_CST)) noexcept {
        __atomic_store_n(&value_, value, static_cast<int>(order));
    }
    template <class Order = int>
    T exchange(T value, Order order = Order(__ATOMIC_SEQ_CST)) noexcept {
        return __atomic_exchange_n(&value_, value, static_cast<int>(order));
    }
    template <class Order = int>
    T fetch_add(T delta, Order order = Order(__ATOMIC_SEQ_CST)) noexcept {
        return __atomic_fetch_add(&value_, delta, static_cast<int>(order));
    }
    template <class Order = int>
    T fetch_sub(T delta, Order order = Order(__ATOMIC_SEQ_CST)) noexcept {
        return __atomic_fetch_sub(&value_, delta, static_cast<int>(order));
    }
    // On failure the order of the load is the weaker of order and acquire.
    template <class Order = int>
    bool compare_exchange_weak(T& expected, T desired, Order order = Order(__ATOMIC_SEQ_CST)) noexcept {
        return __atomic_compare_exchange_n(&value_, &expected, desired, true, static_cast<int>(order),
                                           failure_order(static_cast<int>(order)));
    }
    template <class Order = int>
    bool compare_exchange_strong(T& expected, T desired, Order order = Order(__ATOMIC_SEQ_CST)) noexcept {
        return __atomic_compare_exchange_n(&value_, &expected, desired, false, static_cast<int>(order),
                                           failure_order(static_cast<int>(order)));
    }

private:
    static constexpr int failure_order(int order) noexcept {
        return order == __ATOMIC_ACQ_REL ? __ATOMIC_ACQUIRE : order == __ATOMIC_RELEASE ? __ATOMIC_RELAXED : order;
    }
    T value_;
};

// Atomic's interface over a plain word: the single-thread policy's
// per-instance bookkeeping, which one thread at a time touches (an
// uncontended locked read-modify-write still costs about 20 cycles on x86,
// several per frame). Memory orders are accepted and ignored.
template <class T>
class PlainAtomic {
public:
    constexpr PlainAtomic(T value = T{}) noexcept : value_(value) {}
    PlainAtomic(const PlainAtomic&) = delete;
    PlainAtomic& operator=(const PlainAtomic&) = delete;

    template <class Order = int>
    T load(Order = Order()) const noexcept {
        return value_;
    }
    template <class Order = int>
    void store(T value, Order = Order()) noexcept {
        value_ = value;
    }
    template <class Order = int>
    T exchange(T value, Order = Order()) noexcept {
        const T old = value_;
        value_ = value;
        return old;
    }
    template <class Order = int>
    T fetch_add(T delta, Order = Order()) noexcept {
        const T old = value_;
        value_ = static_cast<T>(old + delta);
        return old;
    }
    template <class Order = int>
    T fetch_sub(T delta, Order = Order()) noexcept {
        const T old = value_;
        value_ = static_cast<T>(old - delta);
        return old;
    }
    template <class Order = int>
    bool compare_exchange_weak(T& expected, T desired, Order = Order()) noexcept {
        return compare_exchange_strong(expected, desired);
    }
    template <class Order = int>
    bool compare_exchange_strong(T& expected, T desired, Order = Order()) noexcept {
        if (value_ != expected) {
            expected = value_;
            return false;
        }
        value_ = desired;
        return true;
    }

private:
    T value_;
};

// MultiThreadPolicy::Mutex's slow paths (src/mutex.cpp). state: 0 unlocked,
// 1 locked, 2 locked with waiters; seen, the value lock()'s exchange found.
void futex_lock_contended(Atomic<std::uint32_t>& state, std::uint32_t seen) noexcept;
void futex_wake_one(Atomic<std::uint32_t>& state) noexcept;
// MultiThreadPolicy::SpinLock's slow path: spins until it takes the lock.
void spin_lock_contended(Atomic<bool>& locked) noexcept;

}  // namespace detail

// Plain count and a lock that does nothing: for programs that touch vkrc
// objects from one thread at a time.
struct SingleThreadPolicy {
    using Count = std::uint32_t;
    // Per-instance bookkeeping words (detail::PolicyAtomic).
    template <class T>
    using Word = detail::PlainAtomic<T>;
    struct Mutex {
        void lock() noexcept {}
        bool try_lock() noexcept { return true; }
        void unlock() noexcept {}
    };
    using SpinLock = Mutex;
    static constexpr bool multi_thread = false;
    static void increment(Count& c) noexcept { ++c; }
    // Increments; true when the count was zero.
    static bool increment_from_zero(Count& c) noexcept { return c++ == 0; }
    // True when the count reached zero.
    static bool decrement(Count& c) noexcept { return --c == 0; }
    // Increments unless the count is zero (the object is being destroyed).
    static bool increment_if_live(Count& c) noexcept { return c != 0 && ++c != 0; }
    static std::uint32_t load(const Count& c) noexcept { return c; }
};

// Atomic count and a real mutex. Increments are relaxed (a new reference can
// only come from an existing one); the decrement is acq_rel so that the thread
// that destroys the object sees every write made through the other references.
struct MultiThreadPolicy {
    using Count = detail::Atomic<std::uint32_t>;
    template <class T>
    using Word = detail::Atomic<T>;
    // A futex mutex (Drepper, "Futexes Are Tricky", mutex 3): uncontended,
    // one compare-exchange to lock and one exchange to unlock, inline; the
    // kernel only when threads contend. A queue submit takes one per frame,
    // where a pthread mutex costs two calls (bench/instructions.sh counts
    // them). Linux only, as vkrc is (its Debian target).
    class Mutex {
    public:
        Mutex() noexcept = default;
        Mutex(const Mutex&) = delete;
        Mutex& operator=(const Mutex&) = delete;
        void lock() noexcept {
            std::uint32_t seen = unlocked;
            if (!state_.compare_exchange_strong(seen, locked, __ATOMIC_ACQUIRE)) [[unlikely]]
                detail::futex_lock_contended(state_, seen);
        }
        bool try_lock() noexcept {
            std::uint32_t seen = unlocked;
            return state_.compare_exchange_strong(seen, locked, __ATOMIC_ACQUIRE);
        }
        void unlock() noexcept {
            if (state_.exchange(unlocked, __ATOMIC_RELEASE) == contended) [[unlikely]]
                detail::futex_wake_one(state_);
        }

    private:
        static constexpr std::uint32_t unlocked = 0, locked = 1, contended = 2;
        detail::Atomic<std::uint32_t> state_{unlocked};
    };
    // For critical sections of a few instructions, where a futex mutex's
    // unlock exchange would cost more than the work: one exchange to lock,
    // one store to unlock.
    class SpinLock {
    public:
        void lock() noexcept {
            if (locked_.exchange(true, __ATOMIC_ACQUIRE)) [[unlikely]]
                detail::spin_lock_contended(locked_);
        }
        void unlock() noexcept { locked_.store(false, __ATOMIC_RELEASE); }

    private:
        detail::Atomic<bool> locked_{false};
    };
    static constexpr bool multi_thread = true;
    static void increment(Count& c) noexcept { c.fetch_add(1, __ATOMIC_RELAXED); }
    static bool increment_from_zero(Count& c) noexcept { return c.fetch_add(1, __ATOMIC_RELAXED) == 0; }
    static bool decrement(Count& c) noexcept { return c.fetch_sub(1, __ATOMIC_ACQ_REL) == 1; }
    static bool increment_if_live(Count& c) noexcept {
        std::uint32_t seen = c.load(__ATOMIC_RELAXED);
        while (seen != 0 && !c.compare_exchange_weak(seen, seen + 1, __ATOMIC_RELAXED)) {}
        return seen != 0;
    }
    static std::uint32_t load(const Count& c) noexcept { return c.load(__ATOMIC_RELAXED); }
};

#if VKRC_IS_MULTI_THREAD
using ThreadPolicy = MultiThreadPolicy;
#else
using ThreadPolicy = SingleThreadPolicy;
#endif
using Mutex = ThreadPolicy::Mutex;
using SpinLock = ThreadPolicy::SpinLock;

namespace detail {
// A word of one instance's bookkeeping (a device's, a queue's, a pool's):
// atomic under vkrc::mt, plain under vkrc::st, where one thread at a time
// touches the instance. Process-wide words stay Atomic under both policies,
// since two instances may live on two threads.
template <class T>
using PolicyAtomic = ThreadPolicy::Word<T>;
}  // namespace detail

// Holds a Mutex (or SpinLock) locked for its scope (std::lock_guard without <mutex>).
template <class Lockable = Mutex>
class LockGuard {
public:
    explicit LockGuard(Lockable& mutex) noexcept : mutex_(mutex) { mutex_.lock(); }
    LockGuard(const LockGuard&) = delete;
    LockGuard& operator=(const LockGuard&) = delete;
    ~LockGuard() { mutex_.unlock(); }

private:
    Lockable& mutex_;
};

namespace detail {

// Creation epochs, process-wide: a state block takes the epoch current at
// its construction as its serial (a load, so that threads making objects at
// once share no written line). current_serial() moves the epoch on, so every
// object made before it has a lower serial: a command buffer ended then may
// refer to objects below that value only (docs/design.md, "Dropped while
// recorded"). Serials are not unique; an object made while another thread
// moves the epoch may get the older value, which only holds its drop longer.
inline Atomic<std::uint64_t> creation_epoch{1};
inline std::uint64_t current_serial() noexcept { return creation_epoch.fetch_add(1, __ATOMIC_RELAXED) + 1; }

// Base of every state block. The count starts at one: the creator owns it.
template <class Policy>
class BasicRefCounted {
public:
    BasicRefCounted() noexcept : serial_(creation_epoch.load(__ATOMIC_RELAXED)) {}
    BasicRefCounted(const BasicRefCounted&) = delete;
    BasicRefCounted& operator=(const BasicRefCounted&) = delete;

    void add_ref() const noexcept { Policy::increment(refs_); }
    // add_ref unless the last reference is already gone (a registry lookup
    // racing the object's destruction, detail::ObjectRegistry).
    bool try_add_ref() const noexcept { return Policy::increment_if_live(refs_); }
    // Drops one reference; on the last one hands the object to on_last_release().
    void release() const noexcept {
        if (Policy::decrement(refs_)) {
            const_cast<BasicRefCounted*>(this)->on_last_release();
        }
    }
    std::uint32_t use_count() const noexcept { return Policy::load(refs_); }
    // The epoch at construction (creation or adoption); see creation_epoch.
    std::uint64_t serial() const noexcept { return serial_; }

protected:
    virtual ~BasicRefCounted() = default;
    // Default: free now. Device children override this to defer destruction
    // until the GPU has finished with them.
    virtual void on_last_release() noexcept { delete this; }
    // add_ref(); true when the count was zero (a state that outlives its
    // last handle, as DeviceState does while it has children, sees a handle
    // to it made again).
    bool add_ref_from_zero() const noexcept { return Policy::increment_from_zero(refs_); }

private:
    mutable typename Policy::Count refs_{1};
    std::uint64_t serial_;
};

using RefCounted = BasicRefCounted<ThreadPolicy>;

// Owning pointer to a state block. Adopts the creator's reference.
template <class T>
class Ref {
public:
    Ref() noexcept = default;
    explicit Ref(T* adopted) noexcept : p_(adopted) {}
    Ref(const Ref& other) noexcept : p_(other.p_) {
        if (p_) p_->add_ref();
    }
    Ref(Ref&& other) noexcept : p_(moves::take(other.p_)) {}
    template <class U>
    Ref(const Ref<U>& other) noexcept : p_(other.get()) {
        if (p_) p_->add_ref();
    }
    // Copy-and-swap: safe for self-assignment in both forms.
    Ref& operator=(Ref other) noexcept {
        swap(other);
        return *this;
    }
    // Through RefCounted: a state type may declare a release() of its own
    // (DeviceAllocator::release(DeviceView) hides the base's).
    ~Ref() {
        if (p_) static_cast<const RefCounted*>(p_)->release();
    }

    // Takes an extra reference to an object already owned elsewhere.
    static Ref share(T* p) noexcept {
        if (p) p->add_ref();
        return Ref(p);
    }
    T* get() const noexcept { return p_; }
    T* operator->() const noexcept { return p_; }
    T& operator*() const noexcept { return *p_; }
    explicit operator bool() const noexcept { return p_ != nullptr; }
    // Gives up ownership without releasing; the caller now owns a reference.
    T* detach() noexcept { return moves::take(p_); }
    void reset() noexcept { Ref().swap(*this); }
    void swap(Ref& other) noexcept { moves::swap_values(p_, other.p_); }

private:
    T* p_ = nullptr;
};

}  // namespace detail

namespace detail {
// Throws UsageError: call (e.g. "vkrc::Buffer::vk") was made through an empty handle.
[[noreturn]] void throw_empty_handle(const char* call);
// The same for the call type::member.
[[noreturn]] void throw_empty_handle(const char* type, const char* member);
}  // namespace detail

// Accessors and recording methods through an empty handle: with
// VKRC_RUNTIME_CHECKS they throw UsageError naming the type and the call (so
// they are not noexcept); without, the check compiles away and an empty
// handle stays a precondition violation (recording stays one call).
// VKRC_REQUIRE_RECORDER is the same check for a CommandRecorder, which has
// its raw handle and no state.
// clang-format off
#if VKRC_RUNTIME_CHECKS
#  define VKRC_UNCHECKED_NOEXCEPT
#  define VKRC_REQUIRE_STATE(...) \
      if (!this->state_) [[unlikely]] ::vkrc::detail::throw_empty_handle(__VA_ARGS__)
#  define VKRC_REQUIRE_RECORDER(...) \
      if (!this->cmd_) [[unlikely]] ::vkrc::detail::throw_empty_handle(__VA_ARGS__)
#else
#  define VKRC_UNCHECKED_NOEXCEPT noexcept
#  define VKRC_REQUIRE_STATE(...) static_cast<void>(0)
#  define VKRC_REQUIRE_RECORDER(...) static_cast<void>(0)
#endif
// clang-format on

// Base of the user-facing wrappers. An empty handle (default-constructed or
// moved-from) holds nothing; calling its accessors is a precondition violation
// (checked with VKRC_RUNTIME_CHECKS: VKRC_REQUIRE_STATE).
template <class State>
class Handle {
public:
    Handle() noexcept = default;
    explicit operator bool() const noexcept { return static_cast<bool>(state_); }
    // Number of handles and child objects that keep this object alive (a
    // Device's children are counted apart: its count is its handles').
    std::uint32_t use_count() const noexcept { return state_ ? state_->use_count() : 0; }
    // Drops this handle's reference.
    void reset() noexcept { state_.reset(); }
    friend bool operator==(const Handle& a, const Handle& b) noexcept { return a.state_.get() == b.state_.get(); }

    // The state block, for vkrc's own code and for extensions built on it.
    State* state() const noexcept { return state_.get(); }

protected:
    explicit Handle(detail::Ref<State> state) noexcept : state_(moves::move(state)) {}
    // The state, for the wrappers' accessors: who (e.g. "vkrc::Buffer::vk")
    // names the call in the UsageError an empty handle gets.
    State& live([[maybe_unused]] const char* who) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_STATE(who);
        return *state_;
    }
    // The same, naming the call type::member (the accessors of a shared base).
    State& live([[maybe_unused]] const char* type, [[maybe_unused]] const char* member) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_STATE(type, member);
        return *state_;
    }
    detail::Ref<State> state_;
};

// Whether a wrapper destroys an adopted raw handle when its last owner goes.
enum class Ownership : std::uint8_t { owned, borrowed };

namespace detail {
// The state of one Vulkan object: its raw handle and whether vkrc destroys
// it. Each family's state derives from it, adds its parent and fields,
// and names its wrapper in type_name (for an empty handle's UsageError).
template <class VkHandle>
class VulkanObjectState : public RefCounted {
public:
    VkHandle handle = VK_NULL_HANDLE;
    Ownership ownership = Ownership::owned;
    // Whether vkrc destroys the handle: it was made (or adopted) and is owned.
    bool owns_handle() const noexcept { return handle != VK_NULL_HANDLE && ownership == Ownership::owned; }
};
}  // namespace detail

namespace detail {
// vk() found the wrapper's copy of the handle differing from its state's: a vkrc bug.
[[noreturn]] void throw_stale_handle(const char* type);
}  // namespace detail

// Base of the wrappers of a VulkanObjectState: the raw handle, copied into
// the wrapper as CommandBuffer copies its own. A state's handle never changes
// once a wrapper exists, and recording reads vk() of every bound object per
// frame: from the wrapper, that is no load from the state's block (fewer
// data-cache misses per frame in callgrind's cache simulation, docs/design.md).
template <class State, class VkHandle>
class VulkanObject : public Handle<State> {
public:
    VkHandle vk() const VKRC_UNCHECKED_NOEXCEPT {
#if VKRC_RUNTIME_CHECKS
        if (this->live(State::type_name, "vk").handle != handle_) [[unlikely]]
            detail::throw_stale_handle(State::type_name);
#endif
        return handle_;
    }
    // Drops this handle's reference (hides Handle::reset, which would leave the copy).
    void reset() noexcept {
        Handle<State>::reset();
        handle_ = VK_NULL_HANDLE;
    }

    VulkanObject(const VulkanObject&) noexcept = default;
    VulkanObject& operator=(const VulkanObject&) noexcept = default;
    // A moved-from wrapper is empty, its copy of the handle included.
    VulkanObject(VulkanObject&& other) noexcept : Handle<State>(moves::move(other)), handle_(other.handle_) {
        other.handle_ = VK_NULL_HANDLE;
    }
    VulkanObject& operator=(VulkanObject&& other) noexcept {
        const VkHandle handle = other.handle_;
        Handle<State>::operator=(moves::move(other));
        other.handle_ = VK_NULL_HANDLE;
        handle_ = handle;
        return *this;
    }

protected:
    VulkanObject() noexcept = default;
    explicit VulkanObject(detail::Ref<State> state) noexcept
        : Handle<State>(moves::move(state)), handle_(this->state_ ? this->state_->handle : VK_NULL_HANDLE) {}

private:
    VkHandle handle_ = VK_NULL_HANDLE;
};

// A raw handle parameter that also takes a vkrc wrapper (any class whose
// vk() returns VkHandle), so one recording method serves both
// cmd.copy_buffer(buffer, ...) and cmd.copy_buffer(raw_buffer, ...). It reads
// the wrapper's vk() at the call and keeps nothing alive.
template <class VkHandle>
class Raw {
public:
    Raw(VkHandle handle) noexcept : handle_(handle) {}
    template <class Wrapper>
    requires requires(const Wrapper& wrapper, void (*take)(VkHandle)) { take(wrapper.vk()); }
    Raw(const Wrapper& wrapper) VKRC_UNCHECKED_NOEXCEPT : handle_(wrapper.vk()) {}
    operator VkHandle() const noexcept { return handle_; }
    // For Vulkan calls that take an array of handles.
    const VkHandle* get() const noexcept { return &handle_; }

private:
    VkHandle handle_;
};

VKRC_END_NAMESPACE
