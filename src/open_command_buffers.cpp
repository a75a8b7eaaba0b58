// OpenCommandBuffers: drops held back while a command buffer that may refer
// to them is open (docs/design.md, "Dropped while recorded").
#include "vkrc/device.hpp"

VKRC_BEGIN_NAMESPACE
namespace detail {

void OpenCommandBuffers::add(RecordingWindow& window) {
    LockGuard lock(mutex_);
    window.index = windows_.size();
    windows_.push_back(&window);
}

void OpenCommandBuffers::remove(DeviceState& device, RecordingWindow& window) noexcept {
    {
        LockGuard lock(mutex_);
        // Swap-remove: the last window takes the removed one's place.
        RecordingWindow* last = windows_[windows_.size() - 1];
        windows_[window.index] = last;
        last->index = window.index;
        windows_.resize(windows_.size() - 1);
    }
    close(device, window);
}

void OpenCommandBuffers::close_pool_slow(DeviceState& device, const void* pool) noexcept {
    if (open_.load() != 0) {
        LockGuard lock(mutex_);
        for (RecordingWindow* w : windows_) {
            if (w->pool == pool && w->end.exchange(0) != 0) open_.fetch_sub(1);
        }
    }
    if (held_count_.load() != 0) release(device);
}

// A recording window counts as ending now: every object that can be dropped
// was made before now, and its end() comes later still.
std::uint64_t OpenCommandBuffers::limit_locked() const noexcept {
    std::uint64_t limit = 0;
    bool recording = false;
    for (const RecordingWindow* w : windows_) {
        const std::uint64_t end = w->end.load();
        if (end == UINT64_MAX) recording = true;
        else if (end > limit) limit = end;
    }
    // Once, however many record: current_serial() moves the epoch on.
    return recording ? current_serial() : limit;
}

std::uint64_t OpenCommandBuffers::limit() noexcept {
    if (open_.load() == 0) return 0;
    LockGuard lock(mutex_);
    return limit_locked();
}

bool OpenCommandBuffers::holds(std::uint64_t serial) noexcept { return serial < limit(); }

bool OpenCommandBuffers::hold(DeferredAction action, std::uint64_t serial) noexcept {
    if (open_.load() == 0) return false;
    LockGuard lock(mutex_);
    const std::uint64_t limit = limit_locked();
    if (serial >= limit) return false;
    try {
        held_.push_back(Held{action, serial});
    } catch (...) {
        return false;  // out of host memory: the deferred queue's own fallback applies
    }
    held_count_.fetch_add(1);
    covered_.store(limit, __ATOMIC_RELAXED);
    // A close racing with this hold may have missed it; collect() looks again.
    stale_.store(true, __ATOMIC_RELAXED);
    return true;
}

void OpenCommandBuffers::release(DeviceState& device) noexcept {
    List<DeferredAction> released;
    {
        LockGuard lock(mutex_);
        stale_.store(false, __ATOMIC_RELAXED);
        const std::uint64_t limit = limit_locked();
        std::size_t kept = 0;
        for (std::size_t i = 0; i < held_.size(); ++i) {
            try {
                if (held_[i].serial >= limit) {
                    released.push_back(held_[i].action);
                    continue;
                }
            } catch (...) {}  // out of host memory: stays held until a later release
            held_[kept++] = held_[i];
        }
        held_.resize(kept);
        held_count_.store(kept);
        covered_.store(limit, __ATOMIC_RELAXED);
    }
    // In order, outside the lock: an action may drop what held it.
    for (const DeferredAction& a : released) device.deferred.destroy_after_gpu(device, a);
}

void OpenCommandBuffers::run_all(DeviceState& device) noexcept {
    for (const Held& h : held_) h.action.run(device, h.action.handle, h.action.context);
    held_.clear();
    held_count_.store(0);
}

}  // namespace detail
VKRC_END_NAMESPACE
