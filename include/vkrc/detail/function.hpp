// vkrc::Function<R(Args...)>: the owning, copyable callable that vkrc's
// create-infos store (the debug callback, the swapchain's log).
//
// Every translation unit that uses vkrc parses its headers; std::function's
// header brings type traits, reference wrappers and type info with it
// (bench/header_cost). Function is the part vkrc needs: it holds any callable
// (a lambda, a function pointer, a std::function), is empty by default or from
// nullptr, tests as a bool and calls through one virtual call. These are
// cold paths (messages and logs), where the heap copy does not matter.
#pragma once

#include "vkrc/detail/moves.hpp"

namespace vkrc {

namespace detail {
template <class A, class B>
inline constexpr bool same_type = false;
template <class A>
inline constexpr bool same_type<A, A> = true;
}  // namespace detail

template <class Signature>
class Function;

template <class R, class... Args>
class Function<R(Args...)> {
public:
    Function() noexcept = default;
    Function(decltype(nullptr)) noexcept {}
    template <class F>
    requires(!detail::same_type<F, Function>) && requires(F& f, Args&&... args) { f(moves::forward<Args>(args)...); }
    Function(F f) : callable_(new Holder<F>(moves::move(f))) {}
    Function(const Function& other) : callable_(other.callable_ ? other.callable_->clone() : nullptr) {}
    Function(Function&& other) noexcept : callable_(moves::take(other.callable_)) {}
    Function& operator=(Function other) noexcept {
        moves::swap_values(callable_, other.callable_);
        return *this;
    }
    ~Function() { delete callable_; }

    explicit operator bool() const noexcept { return callable_ != nullptr; }
    // Calls the held callable; the Function must not be empty.
    R operator()(Args... args) const { return callable_->call(moves::forward<Args>(args)...); }

private:
    struct Callable {
        virtual ~Callable() = default;
        virtual R call(Args&&... args) = 0;
        virtual Callable* clone() const = 0;
    };
    template <class F>
    struct Holder final : Callable {
        explicit Holder(F&& callable) : f(moves::move(callable)) {}
        R call(Args&&... args) override {
            if constexpr (detail::same_type<R, void>)
                f(moves::forward<Args>(args)...);  // drops a result, as std::function does
            else return f(moves::forward<Args>(args)...);
        }
        Callable* clone() const override { return new Holder(F(f)); }
        F f;
    };

    Callable* callable_ = nullptr;
};

}  // namespace vkrc
