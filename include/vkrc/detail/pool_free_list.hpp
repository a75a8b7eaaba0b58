// Deferred freeing of pool-owned handles (command buffers, descriptor sets).
//
// vkFreeCommandBuffers / vkFreeDescriptorSets need the pool alive and
// externally synchronised, which a reference-free DeferredAction cannot
// guarantee. So a dying child's handle goes onto its pool's list, tagged with
// the values submitted so far on every queue; the pool frees the completed
// ones under its own lock at its next allocate/reset/begin, and destroying the
// pool (itself deferred) frees whatever is left.
#pragma once

#include "vkrc/device.hpp"

#include "vkrc/detail/list.hpp"

VKRC_BEGIN_NAMESPACE
namespace detail {

template <class VkHandle>
class PoolFreeList {
public:
    // Caller holds the pool's lock. Never throws: on allocation failure the
    // handle is left to the pool's destruction, which frees it anyway.
    void push(DeviceState& device, VkHandle handle) noexcept {
        try {
            device.submitted_snapshot(scratch_);
            if (batches_.empty() || batches_.back().wait_values != scratch_) batches_.push_back(Batch{scratch_, {}});
            batches_.back().handles.push_back(handle);
        } catch (...) {}
    }
    // Caller holds the pool's lock. Moves the handles whose GPU work has
    // completed into out, in the order they were pushed.
    void take_ready(DeviceState& device, List<VkHandle>& out) {
        std::size_t ready = 0, handles = 0;
        for (; ready < batches_.size() && device.reached(batches_[ready].wait_values); ++ready) {
            handles += batches_[ready].handles.size();
        }
        // The only allocation comes first, so a failure leaves the queue as it was.
        out.reserve(out.size() + handles);
        for (std::size_t i = 0; i < ready; ++i) out.append(batches_[i].handles.data(), batches_[i].handles.size());
        batches_.erase_front(ready);
    }
    bool empty() const noexcept { return batches_.empty(); }
    std::size_t size() const noexcept {
        std::size_t n = 0;
        for (auto& b : batches_) n += b.handles.size();
        return n;
    }
    void clear() noexcept { batches_.clear(); }

private:
    struct Batch {
        List<std::uint64_t> wait_values;
        List<VkHandle> handles;
    };
    List<Batch> batches_;
    List<std::uint64_t> scratch_;
};

}  // namespace detail
VKRC_END_NAMESPACE
