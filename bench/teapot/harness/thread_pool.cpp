#include "harness/thread_pool.hpp"

#include <stdexcept>
#include <utility>

namespace teapot {

ThreadPool::ThreadPool(int threads) : size_(threads), errors_(std::size_t(threads)) {
    if (threads < 1) throw std::invalid_argument("ThreadPool needs at least one thread");
    for (int i = 1; i < threads; ++i) workers_.emplace_back([this, i] { work(i); });
}

ThreadPool::~ThreadPool() {
    stop_ = true;
    generation_.fetch_add(1, std::memory_order_release);
    generation_.notify_all();
    for (std::thread& t : workers_) t.join();
}

void ThreadPool::run_erased(void* job, Call call) {
    job_ = job;
    call_ = call;
    remaining_.store(std::uint32_t(size_ - 1), std::memory_order_relaxed);
    generation_.fetch_add(1, std::memory_order_release);
    if (size_ > 1) generation_.notify_all();
    try {
        call(job, 0);
    } catch (...) {
        errors_[0] = std::current_exception();
    }
    for (std::uint32_t left; (left = remaining_.load(std::memory_order_acquire)) != 0;)
        remaining_.wait(left, std::memory_order_acquire);
    std::exception_ptr first;
    for (std::exception_ptr& error : errors_)
        if (std::exception_ptr e = std::exchange(error, nullptr); e && !first) first = e;
    if (first) std::rethrow_exception(first);
}

void ThreadPool::work(int index) {
    std::uint32_t seen = 0;
    for (;;) {
        generation_.wait(seen, std::memory_order_acquire);
        seen = generation_.load(std::memory_order_acquire);
        if (stop_) return;
        try {
            call_(job_, index);
        } catch (...) {
            errors_[std::size_t(index)] = std::current_exception();
        }
        if (remaining_.fetch_sub(1, std::memory_order_acq_rel) == 1) remaining_.notify_one();
    }
}

}  // namespace teapot
