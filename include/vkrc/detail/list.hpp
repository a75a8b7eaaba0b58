// vkrc::List<T>: the owning array of vkrc's create-infos, results and states.
//
// Every translation unit that uses vkrc parses its headers; <vector> and
// <deque> (with vector<bool>, allocators and their algorithms) were the
// largest part of that (bench/header_cost). List is the little of std::vector
// that vkrc needs: built from a braced list (so `.bindings = {{...}, {...}}`
// keeps working), from any contiguous range (std::vector, std::array,
// std::span, vkrc::Span) or with a count of value-initialised elements. It is a
// contiguous range, so vkrc::Span<const T> takes it as it takes a vector.
#pragma once

#include "vkrc/detail/moves.hpp"
#include "vkrc/detail/span.hpp"

#include <cstddef>
#include <initializer_list>
#include <new>

namespace vkrc {

template <class T>
class List {
public:
    List() noexcept = default;
    // The constructors delegate to List() so that, should a copy throw, the
    // destructor frees what was made.
    List(std::initializer_list<T> items) : List() { append_copies(items.begin(), items.size()); }
    List(const T* items, std::size_t count) : List() { append_copies(items, count); }
    // Any contiguous range of T: std::vector, std::array, std::span, vkrc::Span,
    // List (the rule Span views by: no base-class copies of derived elements).
    template <detail::range_of<const T> Range>
    List(const Range& items) : List() {
        append_copies(items.data(), items.size());
    }
    // count value-initialised elements, made in place (T need not be movable).
    explicit List(std::size_t count) : List() {
        data_ = allocate(count);
        capacity_ = count;
        for (; size_ < count; ++size_) new (data_ + size_) T();
    }
    List(const List& other) : List() { append_copies(other.data_, other.size_); }
    List(List&& other) noexcept { swap(other); }
    List& operator=(const List& other) {
        if (this != &other) List(other).swap(*this);
        return *this;
    }
    List& operator=(List&& other) noexcept {
        List(moves::move(other)).swap(*this);
        return *this;
    }
    ~List() {
        clear();
        ::operator delete(data_);
    }

    std::size_t size() const noexcept { return size_; }
    bool empty() const noexcept { return size_ == 0; }
    T* data() noexcept { return data_; }
    const T* data() const noexcept { return data_; }
    T* begin() noexcept { return data_; }
    T* end() noexcept { return data_ + size_; }
    const T* begin() const noexcept { return data_; }
    const T* end() const noexcept { return data_ + size_; }
    T& operator[](std::size_t i) noexcept { return data_[i]; }
    const T& operator[](std::size_t i) const noexcept { return data_[i]; }
    T& front() noexcept { return data_[0]; }
    const T& front() const noexcept { return data_[0]; }
    T& back() noexcept { return data_[size_ - 1]; }
    const T& back() const noexcept { return data_[size_ - 1]; }

    // Appends one element, growing the storage geometrically.
    T& push_back(T item) {
        if (size_ == capacity_) reserve(capacity_ == 0 ? 4 : capacity_ * 2);
        new (data_ + size_) T(moves::move(item));
        return data_[size_++];
    }
    // Drops the last element; the list must not be empty.
    void pop_back() noexcept { data_[--size_].~T(); }
    // Appends copies of count items.
    void append(const T* items, std::size_t count) { append_copies(items, count); }
    // Grows with value-initialised elements or drops the last ones; keeps the storage.
    void resize(std::size_t count) {
        if (count <= size_) {
            while (size_ > count) data_[--size_].~T();
            return;
        }
        reserve(count);
        for (; size_ < count; ++size_) new (data_ + size_) T();
    }
    // Removes the first count elements (at most size()), moving the rest down
    // once: a List used as a queue drains what is ready in one pass.
    void erase_front(std::size_t count) noexcept {
        for (std::size_t i = count; i < size_; ++i) data_[i - count] = moves::move(data_[i]);
        while (count-- > 0) data_[--size_].~T();
    }
    void clear() noexcept {
        while (size_ > 0) data_[--size_].~T();
    }
    void reserve(std::size_t capacity) {
        if (capacity <= capacity_) return;
        T* grown = allocate(capacity);
        for (std::size_t i = 0; i < size_; ++i) {
            new (grown + i) T(moves::move(data_[i]));
            data_[i].~T();
        }
        ::operator delete(data_);
        data_ = grown;
        capacity_ = capacity;
    }
    void swap(List& other) noexcept {
        moves::swap_values(data_, other.data_);
        moves::swap_values(size_, other.size_);
        moves::swap_values(capacity_, other.capacity_);
    }

    friend bool operator==(const List& a, const List& b) {
        if (a.size_ != b.size_) return false;
        for (std::size_t i = 0; i < a.size_; ++i)
            if (!(a.data_[i] == b.data_[i])) return false;
        return true;
    }

private:
    static T* allocate(std::size_t count) { return static_cast<T*>(::operator new(count * sizeof(T))); }
    // Copies count items to the end; a copy that throws leaves those made before it.
    void append_copies(const T* items, std::size_t count) {
        reserve(size_ + count);
        for (std::size_t i = 0; i < count; ++i, ++size_) new (data_ + size_) T(items[i]);
    }

    T* data_ = nullptr;
    std::size_t size_ = 0;
    std::size_t capacity_ = 0;
};

}  // namespace vkrc
