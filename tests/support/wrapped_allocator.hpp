// A test allocator around vkrc's PoolAllocator: each range it makes carries
// the pool's own view of it, so that a subclass may fail, count or watch
// the calls and leave the work to the pool.
#pragma once

#include <vkrc/vkrc.hpp>

#include <atomic>

namespace vkrc_test {

class WrappedPoolAllocator : public vkrc::DeviceAllocator {
public:
    vkrc::AllocationInfo allocate(vkrc::DeviceView device, const vkrc::AllocationRequest& request) override {
        auto info = inner_.allocate(device, request);
        info.allocator_data = new vkrc::AllocationInfo(info);  // the pool's own view
        info.allocator = this;
        return info;
    }
    void free(vkrc::DeviceView device, const vkrc::AllocationInfo& allocation) override {
        auto* inner = static_cast<vkrc::AllocationInfo*>(allocation.allocator_data);
        inner_.free(device, *inner);
        delete inner;
    }
    void release(vkrc::DeviceView device) noexcept override { inner_.release(device); }

private:
    vkrc::PoolAllocator inner_;
};

// The pool, counting what it frees: objects made from one show memory that
// held work still needs freed before the work may run (lavapipe would read
// the stale bytes unharmed, so the results alone would not show it).
class CountingAllocator final : public WrappedPoolAllocator {
public:
    void free(vkrc::DeviceView device, const vkrc::AllocationInfo& allocation) override {
        WrappedPoolAllocator::free(device, allocation);
        ++frees_;
    }
    // The device calls release() once, at its teardown: this shows when it went.
    void release(vkrc::DeviceView device) noexcept override {
        WrappedPoolAllocator::release(device);
        ++releases_;
    }
    int frees() const { return frees_; }
    int releases() const { return releases_; }

private:
    std::atomic<int> frees_{0};
    std::atomic<int> releases_{0};
};

}  // namespace vkrc_test
