// The recording threads of the command stage with --threads N (issue 17),
// one machinery for every variant: N - 1 persistent workers, created once
// per configuration and woken once per frame, plus the calling thread.
// run(job) calls job(i) for every i in [0, N): i = 0 on the calling thread
// (it would only wait otherwise), the others on the workers, and returns
// once all are done, rethrowing the first exception a job threw.
#pragma once

#include <atomic>
#include <cstdint>
#include <exception>
#include <thread>
#include <vector>

namespace teapot {

class ThreadPool {
public:
    explicit ThreadPool(int threads);
    ~ThreadPool();
    ThreadPool(const ThreadPool&) = delete;
    ThreadPool& operator=(const ThreadPool&) = delete;

    int size() const { return size_; }

    template <typename Job>
    void run(Job& job) {
        run_erased(&job, [](void* j, int i) { (*static_cast<Job*>(j))(i); });
    }

private:
    using Call = void (*)(void*, int);
    void run_erased(void* job, Call call);
    void work(int index);

    int size_;
    // Published by the generation's increment (release), read after it (acquire).
    void* job_ = nullptr;
    Call call_ = nullptr;
    bool stop_ = false;
    std::vector<std::exception_ptr> errors_;  // [thread]: written by its thread, read after the latch
    // 32-bit, so that wait/notify are plain futex operations.
    std::atomic<std::uint32_t> generation_{0};
    std::atomic<std::uint32_t> remaining_{0};
    std::vector<std::thread> workers_;
};

// The draws thread i of n records: an even split, the first ones first, so
// that executing the secondaries in thread order draws in the 1-thread order.
struct DrawRange {
    std::size_t first = 0, last = 0;
};
inline DrawRange draw_range(int i, int n, std::size_t count) {
    return {count * std::size_t(i) / std::size_t(n), count * std::size_t(i + 1) / std::size_t(n)};
}

}  // namespace teapot
