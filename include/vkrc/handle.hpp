// The handle model: intrusive reference counts under a thread policy.
//
// Every vkrc object is one heap block (a "state") that holds the Vulkan
// handle, the references to its parents and the count. User-facing wrappers
// (Instance, Device, Buffer, ...) are Handle<State>: one pointer, copy shares,
// move transfers, the last owner releases the state.
#pragma once

#include "vkrc/config.hpp"
#include "vkrc/detail/light_std.hpp"  // std::mutex, std::lock_guard

#include <atomic>
#include <cstdint>
#include <utility>

VKRC_BEGIN_NAMESPACE

// Plain count and a lock that does nothing: for programs that touch vkrc
// objects from one thread at a time.
struct SingleThreadPolicy {
    using Count = std::uint32_t;
    struct Mutex {
        void lock() noexcept {}
        bool try_lock() noexcept { return true; }
        void unlock() noexcept {}
    };
    static constexpr bool multi_thread = false;
    static void increment(Count& c) noexcept { ++c; }
    // True when the count reached zero.
    static bool decrement(Count& c) noexcept { return --c == 0; }
    static std::uint32_t load(const Count& c) noexcept { return c; }
};

// Atomic count and a real mutex. Increments are relaxed (a new reference can
// only come from an existing one); the decrement is acq_rel so that the thread
// that destroys the object sees every write made through the other references.
struct MultiThreadPolicy {
    using Count = std::atomic<std::uint32_t>;
    using Mutex = std::mutex;
    static constexpr bool multi_thread = true;
    static void increment(Count& c) noexcept { c.fetch_add(1, std::memory_order_relaxed); }
    static bool decrement(Count& c) noexcept { return c.fetch_sub(1, std::memory_order_acq_rel) == 1; }
    static std::uint32_t load(const Count& c) noexcept { return c.load(std::memory_order_relaxed); }
};

#if VKRC_IS_MULTI_THREAD
using ThreadPolicy = MultiThreadPolicy;
#else
using ThreadPolicy = SingleThreadPolicy;
#endif
using Mutex = ThreadPolicy::Mutex;
using LockGuard = std::lock_guard<Mutex>;

namespace detail {

// Base of every state block. The count starts at one: the creator owns it.
template <class Policy>
class BasicRefCounted {
public:
    BasicRefCounted() = default;
    BasicRefCounted(const BasicRefCounted&) = delete;
    BasicRefCounted& operator=(const BasicRefCounted&) = delete;

    void add_ref() const noexcept { Policy::increment(refs_); }
    // Drops one reference; on the last one hands the object to on_last_release().
    void release() const noexcept {
        if (Policy::decrement(refs_)) {
            const_cast<BasicRefCounted*>(this)->on_last_release();
        }
    }
    std::uint32_t use_count() const noexcept { return Policy::load(refs_); }

protected:
    virtual ~BasicRefCounted() = default;
    // Default: free now. Device children override this to defer destruction
    // until the GPU has finished with them.
    virtual void on_last_release() noexcept { delete this; }

private:
    mutable typename Policy::Count refs_{1};
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
    Ref(Ref&& other) noexcept : p_(std::exchange(other.p_, nullptr)) {}
    template <class U>
    Ref(const Ref<U>& other) noexcept : p_(other.get()) {
        if (p_) p_->add_ref();
    }
    // Copy-and-swap: safe for self-assignment in both forms.
    Ref& operator=(Ref other) noexcept {
        std::swap(p_, other.p_);
        return *this;
    }
    ~Ref() {
        if (p_) p_->release();
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
    T* detach() noexcept { return std::exchange(p_, nullptr); }
    void reset() noexcept { Ref().swap(*this); }
    void swap(Ref& other) noexcept { std::swap(p_, other.p_); }

private:
    T* p_ = nullptr;
};

}  // namespace detail

// Base of the user-facing wrappers. An empty handle (default-constructed or
// moved-from) holds nothing; calling its accessors is a precondition violation.
template <class State>
class Handle {
public:
    Handle() noexcept = default;
    explicit operator bool() const noexcept { return static_cast<bool>(state_); }
    // Number of handles and child objects that keep this object alive.
    std::uint32_t use_count() const noexcept { return state_ ? state_->use_count() : 0; }
    // Drops this handle's reference.
    void reset() noexcept { state_.reset(); }
    friend bool operator==(const Handle& a, const Handle& b) noexcept {
        return a.state_.get() == b.state_.get();
    }

    // The state block, for vkrc's own code and for extensions built on it.
    State* state() const noexcept { return state_.get(); }

protected:
    explicit Handle(detail::Ref<State> state) noexcept : state_(std::move(state)) {}
    detail::Ref<State> state_;
};

// Whether a wrapper destroys an adopted raw handle when its last owner goes.
enum class Ownership : std::uint8_t { owned, borrowed };

VKRC_END_NAMESPACE
