// Deferred freeing of pool-owned handles (command buffers, descriptor sets).
//
// vkFreeCommandBuffers / vkFreeDescriptorSets need the pool alive and
// externally synchronised, which a reference-free DeferredAction cannot
// guarantee. So a dying child's handle goes onto its pool's list, tagged with
// the values submitted so far on every queue; the pool frees (or, for
// descriptor sets, reuses) the completed ones under its own lock at its next
// allocate/reset/begin, and destroying the pool (itself deferred) frees
// whatever is left. Entry: the raw handle, or a struct holding it and what
// the pool keeps with it; entries are moved, never copied.
#pragma once

#include "vkrc/device.hpp"

#include "vkrc/detail/list.hpp"

VKRC_BEGIN_NAMESPACE
namespace detail {

template <class Entry>
class PoolFreeList {
public:
    // Caller holds the pool's lock. serial: the dying child's. Never throws:
    // on allocation failure the entry is dropped and its handle left to the
    // pool's destruction, which frees it anyway.
    void push(DeviceState& device, Entry entry, std::uint64_t serial) noexcept {
        try {
            // An open command buffer may still refer to it (OpenCommandBuffers).
            if (device.held_back(serial)) {
                held_.push_back(Held{moves::move(entry), serial});
                return;
            }
            push_now(device, entry);
        } catch (...) {}
    }
    // Caller holds the pool's lock. Moves the entries whose GPU work has
    // completed to the end of out.
    void take_ready(DeviceState& device, List<Entry>& out) {
        if (!held_.empty()) release_held(device);
        std::size_t ready = 0, handles = ready_.size();
        for (; ready < batches_.size() && device.reached(batches_[ready].wait_values); ++ready) {
            handles += batches_[ready].handles.size();
        }
        // The only allocation comes first, so a failure leaves the queue as it was.
        out.reserve(out.size() + handles);
        for (Entry& entry : ready_) out.push_back(moves::move(entry));
        ready_.clear();
        for (std::size_t i = 0; i < ready; ++i) {
            for (Entry& entry : batches_[i].handles) out.push_back(moves::move(entry));
        }
        batches_.erase_front(ready);
    }
    bool empty() const noexcept { return ready_.empty() && batches_.empty() && held_.empty(); }
    std::size_t size() const noexcept {
        std::size_t n = ready_.size() + held_.size();
        for (auto& b : batches_) n += b.handles.size();
        return n;
    }
    void clear() noexcept {
        ready_.clear();
        batches_.clear();
        held_.clear();
    }

private:
    struct Batch {
        List<std::uint64_t> wait_values;
        List<Entry> handles;
    };
    struct Held {
        Entry entry;
        std::uint64_t serial;
    };
    // Moves entry in, or leaves it as it was when out of host memory. When
    // the work it waits for is already known complete (nothing in flight), it
    // is ready at once: no batch is made for it, nor freed for it later.
    void push_now(DeviceState& device, Entry& entry) {
        device.submitted_snapshot(scratch_);
        List<Entry>* handles = &ready_;
        if (!device.known_reached(scratch_)) {
            if (batches_.empty() || batches_.back().wait_values != scratch_) batches_.push_back(Batch{scratch_, {}});
            handles = &batches_.back().handles;
        }
        handles->reserve(handles->size() + 1);
        handles->push_back(moves::move(entry));
    }
    // The held handles no open command buffer refers to any more wait for
    // the work submitted so far, like a fresh drop; the others stay, in order.
    void release_held(DeviceState& device) {
        const std::uint64_t limit = device.hold_limit();
        std::size_t kept = 0;
        for (std::size_t i = 0; i < held_.size(); ++i) {
            try {
                if (held_[i].serial >= limit) {
                    push_now(device, held_[i].entry);
                    continue;
                }
            } catch (...) {}  // out of host memory: stays held until a later try
            if (kept != i) held_[kept] = moves::move(held_[i]);
            ++kept;
        }
        held_.resize(kept);
    }
    List<Entry> ready_;  // pushed when their work was already complete
    List<Batch> batches_;
    List<Held> held_;
    List<std::uint64_t> scratch_;
};

}  // namespace detail
VKRC_END_NAMESPACE
