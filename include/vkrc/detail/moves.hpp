// The moves of vkrc's owning members, written once by hand: std::exchange
// and std::swap would be instantiated for each member type in every
// translation unit that includes vkrc, and <utility> (std::move, std::forward)
// brings <compare> and std::pair with it (bench/header_cost). A namespace of
// their own, which vkrc and its policy namespaces both reach as moves::.
#pragma once

namespace vkrc::moves {

template <class T>
struct Unref {
    using type = T;
};
template <class T>
struct Unref<T&> {
    using type = T;
};
template <class T>
struct Unref<T&&> {
    using type = T;
};

// std::move.
template <class T>
constexpr typename Unref<T>::type&& move(T&& value) noexcept {
    return static_cast<typename Unref<T>::type&&>(value);
}

// std::forward.
template <class T>
constexpr T&& forward(typename Unref<T>::type& value) noexcept {
    return static_cast<T&&>(value);
}

// p's value, leaving p null: a move constructor's steal.
template <class T>
T* take(T*& p) noexcept {
    T* taken = p;
    p = nullptr;
    return taken;
}

// Exchanges two plain values (pointers, sizes): copy-and-swap assignment.
template <class T>
void swap_values(T& a, T& b) noexcept {
    T kept = a;
    a = b;
    b = kept;
}

}  // namespace vkrc::moves
