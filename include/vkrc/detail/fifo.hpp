// vkrc::Fifo<T>: a growable ring of T for work that retires in submission
// order (a queue's batches complete in the order they were submitted).
//
// List::erase_front moves every remaining element; with hundreds of batches
// in flight that made each retirement cost hundreds of moves. Here pushing
// at the back and popping at the front are O(1); the storage doubles when
// full and is never shrunk. T must be default-constructible and movable: a
// popped slot is reset to T{} so that it holds no resource.
#pragma once

#include "vkrc/detail/list.hpp"

#include <cstddef>

namespace vkrc {

template <class T>
class Fifo {
public:
    std::size_t size() const noexcept { return size_; }
    bool empty() const noexcept { return size_ == 0; }
    // i counts from the front (0) to the back (size() - 1).
    T& operator[](std::size_t i) noexcept { return slots_[(head_ + i) & (slots_.size() - 1)]; }
    const T& operator[](std::size_t i) const noexcept { return slots_[(head_ + i) & (slots_.size() - 1)]; }
    T& front() noexcept { return (*this)[0]; }
    const T& front() const noexcept { return (*this)[0]; }
    T& back() noexcept { return (*this)[size_ - 1]; }
    const T& back() const noexcept { return (*this)[size_ - 1]; }

    void push_back(T item) {
        if (size_ == slots_.size()) grow();
        (*this)[size_++] = moves::move(item);
    }
    // Removes the first count elements (at most size()).
    void pop_front(std::size_t count = 1) noexcept {
        for (; count > 0 && size_ > 0; --count, --size_) {
            front() = T{};
            head_ = (head_ + 1) & (slots_.size() - 1);
        }
    }

private:
    // Power-of-two capacity, so that an index wraps with a mask.
    void grow() {
        List<T> grown(slots_.empty() ? 8 : slots_.size() * 2);
        for (std::size_t i = 0; i < size_; ++i) grown[i] = moves::move((*this)[i]);
        slots_.swap(grown);
        head_ = 0;
    }

    List<T> slots_;
    std::size_t head_ = 0;
    std::size_t size_ = 0;
};

}  // namespace vkrc
