// vkrc::Span<T>: the borrowed arrays of vkrc's API (a pointer and a count).
//
// Every translation unit that uses vkrc parses its headers; <span> brings
// <array>, the ranges machinery and the iterator concepts with it, about a
// fifth of what vkrc cost a translation unit (bench/header_cost). Span is the
// part of std::span that vkrc needs: made from a pointer and a count, from a
// C array, or from any contiguous range with data() and size() (std::span,
// std::vector, std::array, vkrc::List); a std::span of const elements takes
// it back as it takes any contiguous range. Like std::span it owns nothing:
// what it points to must outlive it.
#pragma once

#include <cstddef>

namespace vkrc {

namespace detail {
template <class T>
T& lvalue() noexcept;  // declared only, for decltype (std::declval without <utility>)
template <class Pointer>
struct Pointee {};
template <class E>
struct Pointee<E*> {
    using type = E;
};
// The element type of a range's data() pointer.
template <class Range>
using RangeElement = typename Pointee<decltype(lvalue<Range>().data())>::type;
// Elements of type From can be viewed as T: the same type, at most adding
// const (an array pointer converts only so; a Span of a base class must not
// take an array of derived ones).
template <class From, class T>
concept viewable_as = requires(From (*from)[], void (*to)(T (*)[])) {
    to(from);
};
// A range with size() (its data() is RangeElement's part).
template <class Range>
concept sized = requires(Range& r) {
    r.size();
};
// A contiguous range (data() and size()) whose elements can be viewed as T.
template <class Range, class T>
concept range_of = sized<Range> && viewable_as<RangeElement<Range>, T>;
}  // namespace detail

template <class T>
class Span {
public:
    using element_type = T;

    constexpr Span() noexcept = default;
    constexpr Span(T* data, std::size_t size) noexcept : data_(data), size_(size) {}
    template <std::size_t N>
    constexpr Span(T (&items)[N]) noexcept : data_(items), size_(N) {}
    // Any contiguous range whose elements are T (or non-const T for a Span of const T).
    template <detail::range_of<T> Range>
    constexpr Span(Range&& items) noexcept : data_(items.data()), size_(items.size()) {}

    constexpr T* data() const noexcept { return data_; }
    constexpr std::size_t size() const noexcept { return size_; }
    constexpr std::size_t size_bytes() const noexcept { return size_ * sizeof(T); }
    constexpr bool empty() const noexcept { return size_ == 0; }
    constexpr T* begin() const noexcept { return data_; }
    constexpr T* end() const noexcept { return data_ + size_; }
    constexpr T& operator[](std::size_t i) const noexcept { return data_[i]; }
    constexpr T& front() const noexcept { return data_[0]; }
    constexpr T& back() const noexcept { return data_[size_ - 1]; }
    // count elements from offset (the caller keeps both in range, as with std::span).
    constexpr Span subspan(std::size_t offset, std::size_t count) const noexcept { return {data_ + offset, count}; }

private:
    T* data_ = nullptr;
    std::size_t size_ = 0;
};

template <class T>
Span(T*, std::size_t) -> Span<T>;
template <class T, std::size_t N>
Span(T (&)[N]) -> Span<T>;
template <class Range>
Span(Range&&) -> Span<detail::RangeElement<Range>>;

}  // namespace vkrc
