// Synchronisation objects: Fence, Semaphore (binary and timeline), Event, QueryPool.
//
// Waits return a VkResult: VK_TIMEOUT is a status to branch on, not an
// exception. Every wait runs the device's completed deferred destructions.
#pragma once

#include "vkrc/device.hpp"

#include "vkrc/detail/span.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
class FenceState;
class SemaphoreState;
class EventState;
class QueryPoolState;
}  // namespace detail

inline constexpr std::uint64_t wait_forever = UINT64_MAX;

class Fence : public DeviceChild<detail::FenceState, VkFence> {
public:
    // signaled: created in the signalled state (VK_FENCE_CREATE_SIGNALED_BIT).
    static Fence create(const Device& device, bool signaled = false);
    static Fence adopt(const Device& device, VkFence fence, Ownership ownership);

    // vkWaitForFences: VK_SUCCESS, or VK_TIMEOUT when timeout_ns passed first.
    // After VK_SUCCESS for a fence given to vkrc::submit, every object dropped
    // before that submission has been destroyed. Inline, as unsignal(): a
    // frame calls both.
    VkResult wait(std::uint64_t timeout_ns = wait_forever) const;
    // vkGetFenceStatus: VK_SUCCESS (signalled) or VK_NOT_READY.
    VkResult status() const;
    // vkResetFences (reset() drops the handle, as on every handle).
    void unsignal() const;

private:
    using DeviceChild::DeviceChild;
};

enum class SemaphoreType : std::uint8_t { binary, timeline };

class Semaphore : public DeviceChild<detail::SemaphoreState, VkSemaphore> {
public:
    static Semaphore create_binary(const Device& device);
    static Semaphore create_timeline(const Device& device, std::uint64_t initial_value = 0);
    static Semaphore adopt(const Device& device, VkSemaphore semaphore, SemaphoreType type, Ownership ownership);

    SemaphoreType type() const VKRC_UNCHECKED_NOEXCEPT;

    // Timeline semaphores only (UsageError otherwise).
    // vkGetSemaphoreCounterValue.
    std::uint64_t value() const;
    // vkSignalSemaphore from the host.
    void signal(std::uint64_t value) const;
    // vkWaitSemaphores: VK_SUCCESS once the value is reached, or VK_TIMEOUT.
    VkResult wait(std::uint64_t value, std::uint64_t timeout_ns = wait_forever) const;

private:
    using DeviceChild::DeviceChild;
};

class Event : public DeviceChild<detail::EventState, VkEvent> {
public:
    // device_only: VK_EVENT_CREATE_DEVICE_ONLY_BIT (no host set/reset/status).
    static Event create(const Device& device, bool device_only = false);
    // Wraps one made elsewhere from device. With Ownership::owned vkrc destroys
    // it once the GPU is done; borrowed, its maker does (after vkrc's last use).
    static Event adopt(const Device& device, VkEvent event, Ownership ownership);

    // vkSetEvent / vkResetEvent (reset() drops the handle, as on every handle).
    void set() const;
    void unset() const;
    // VK_EVENT_SET or VK_EVENT_RESET.
    VkResult status() const;

private:
    using DeviceChild::DeviceChild;
};

// Mirrors VkQueryPoolCreateInfo.
struct QueryPoolCreateInfo {
    // Optional (default timestamps).
    VkQueryType query_type = VK_QUERY_TYPE_TIMESTAMP;
    // Required, non-zero.
    std::uint32_t query_count = 0;
    // For pipeline-statistics pools only (default none).
    VkQueryPipelineStatisticFlags pipeline_statistics = 0;
    // Optional pNext chain; read during create only.
    const void* next = nullptr;
};

class QueryPool : public DeviceChild<detail::QueryPoolState, VkQueryPool> {
public:
    static QueryPool create(const Device& device, const QueryPoolCreateInfo& info);
    // Wraps a pool made elsewhere from device; info: what it was made with
    // (read during the call). Ownership as for Event::adopt.
    static QueryPool adopt(const Device& device, VkQueryPool pool, const QueryPoolCreateInfo& info,
                           Ownership ownership);

    std::uint32_t query_count() const VKRC_UNCHECKED_NOEXCEPT;
    // Reset queries before use with CommandBuffer::reset_query_pool.
    // vkGetQueryPoolResults as 64-bit values into out, tightly packed: the
    // queries read are out.size() / words_per_query(flags) from first_query.
    // UsageError when out is empty or its size is not a multiple of that (so
    // no value of out is left unwritten) or the queries exceed the pool.
    // VK_NOT_READY when flags lack WAIT and some are not ready.
    VkResult results(std::uint32_t first_query, Span<std::uint64_t> out,
                     VkQueryResultFlags flags = VK_QUERY_RESULT_WAIT_BIT) const;
    // Nanoseconds per timestamp tick: the physical device's
    // VkPhysicalDeviceLimits::timestampPeriod, offered here beside the ticks.
    double timestamp_period_ns() const VKRC_UNCHECKED_NOEXCEPT;
    VkQueryType query_type() const VKRC_UNCHECKED_NOEXCEPT;
    // Values per query: one per statistic for a pipeline statistics pool, otherwise 1.
    std::uint32_t values_per_query() const VKRC_UNCHECKED_NOEXCEPT;
    // The 64-bit words results() writes per query with flags: values_per_query(),
    // plus one with WITH_AVAILABILITY or WITH_STATUS_KHR.
    std::uint32_t words_per_query(VkQueryResultFlags flags = VK_QUERY_RESULT_WAIT_BIT) const VKRC_UNCHECKED_NOEXCEPT;

private:
    using DeviceChild::DeviceChild;
};

namespace detail {

class FenceState final : public DeviceChildState<VkFence> {
public:
    static constexpr const char* type_name = "vkrc::Fence";
    ~FenceState() override;
    // Set by vkrc::submit (DeviceState::submit), kept until the fence is
    // seen signalled or unsignal() resets it. A fence signal covers all work
    // submitted before it on that queue, so deferred destructions waiting for
    // it run at that wait. A fence reset without unsignal() (raw
    // vkResetFences) must have been waited for first, so the record never
    // claims work that is pending. Written only by submit, wait, status and
    // unsignal, which Vulkan already requires to be externally synchronised
    // for the fence.
    FencedSubmission submission;
    // Submitted and not yet seen signalled: the queue timeline passing its
    // value does not mean the fence's own signal operation has completed,
    // so destruction then waits for the fence (see destroy_submitted_fence).
    bool in_flight() const noexcept { return submission.queue != nullptr; }
    // After a successful wait or status: records the submission as complete.
    void note_signalled() noexcept {
        if (QueueState* q = submission.queue) {
            q->timeline.note_completed(submission.number);
            submission.queue = nullptr;
        }
    }
    // Fence::unsignal reset the fence: it stands for no submission any more.
    void note_unsignalled() noexcept { submission.queue = nullptr; }
    // After vkWaitForFences or vkGetFenceStatus returned r: a signalled
    // fence is no longer in flight; then DeviceState::finish_call.
    VkResult finish_query(VkResult r, const char* call) {
        if (r == VK_SUCCESS) note_signalled();
        return device.state()->finish_call(r, call);
    }
};

// Queues the destruction of a fence that was submitted and may not have been
// seen signalled: after the work submitted so far, it waits for the fence
// (at once in practice; a lost device returns at once too), then destroys it.
void destroy_submitted_fence(DeviceState& device, VkFence fence, std::uint64_t serial) noexcept;

class SemaphoreState final : public DeviceChildState<VkSemaphore> {
public:
    static constexpr const char* type_name = "vkrc::Semaphore";
    ~SemaphoreState() override;
    SemaphoreType type = SemaphoreType::binary;
};

class EventState final : public DeviceChildState<VkEvent> {
public:
    static constexpr const char* type_name = "vkrc::Event";
    ~EventState() override;
};

class QueryPoolState final : public DeviceChildState<VkQueryPool> {
public:
    static constexpr const char* type_name = "vkrc::QueryPool";
    ~QueryPoolState() override;
    std::uint32_t count = 0;
    VkQueryType type = VK_QUERY_TYPE_TIMESTAMP;
    std::uint32_t values_per_query = 1;
};

}  // namespace detail

inline VkResult Fence::wait(std::uint64_t timeout_ns) const {
    auto& s = live("vkrc::Fence::wait");
    const auto& d = *s.device.state();
    return s.finish_query(d.fn.vkWaitForFences(d.device, 1, &s.handle, VK_TRUE, timeout_ns), "vkWaitForFences");
}
inline void Fence::unsignal() const {
    auto& s = live("vkrc::Fence::unsignal");
    const auto& d = *s.device.state();
    check(d.fn.vkResetFences(d.device, 1, &s.handle), "vkResetFences");
    s.note_unsignalled();
}

inline SemaphoreType Semaphore::type() const VKRC_UNCHECKED_NOEXCEPT { return live("vkrc::Semaphore::type").type; }
inline std::uint32_t QueryPool::query_count() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::QueryPool::query_count").count;
}
inline VkQueryType QueryPool::query_type() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::QueryPool::query_type").type;
}
inline std::uint32_t QueryPool::values_per_query() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::QueryPool::values_per_query").values_per_query;
}

VKRC_END_NAMESPACE
