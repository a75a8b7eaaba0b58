#include "vkrc/sync.hpp"

#include "caller.hpp"
#include "object_state.hpp"

#include <bit>
#include <string>

VKRC_BEGIN_NAMESPACE

namespace detail {
void destroy_submitted_fence(DeviceState& device, VkFence fence, std::uint64_t serial) noexcept {
    if (fence == VK_NULL_HANDLE) return;
    device.destroy_after_gpu({[](DeviceState& d, std::uint64_t bits, void*) noexcept {
                                  auto f = handle_from_bits<VkFence>(bits);
                                  d.fn.vkWaitForFences(d.device, 1, &f, VK_TRUE, UINT64_MAX);
                                  d.fn.vkDestroyFence(d.device, f, nullptr);
                              },
                              handle_bits(fence), nullptr},
                             serial);
}

FenceState::~FenceState() {
    if (in_flight() && ownership == Ownership::owned) {
        destroy_submitted_fence(*device.state(), handle, serial());
    } else {
        destroy_owned<&DeviceFunctions::vkDestroyFence>(*this, device);
    }
}
SemaphoreState::~SemaphoreState() { destroy_owned<&DeviceFunctions::vkDestroySemaphore>(*this, device); }
EventState::~EventState() { destroy_owned<&DeviceFunctions::vkDestroyEvent>(*this, device); }
QueryPoolState::~QueryPoolState() { destroy_owned<&DeviceFunctions::vkDestroyQueryPool>(*this, device); }
}  // namespace detail

Fence Fence::create(const Device& device, bool signaled) {
    detail::Caller("vkrc::Fence::create").require_handle(device, "the Device");
    VkFenceCreateInfo ci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    if (signaled) ci.flags = VK_FENCE_CREATE_SIGNALED_BIT;
    return Fence(
        detail::created_state<detail::FenceState, &DeviceFunctions::vkCreateFence>(device, ci, "vkCreateFence"));
}

Fence Fence::adopt(const Device& device, VkFence fence, Ownership ownership) {
    return Fence(detail::adopted_state<detail::FenceState>(detail::Caller{"vkrc::Fence::adopt"}, device, "the Device",
                                                           fence, "VkFence", ownership));
}

VkResult Fence::status() const {
    const auto& d = state_->device;
    return state_->finish_query(d.fn().vkGetFenceStatus(d.vk(), state_->handle), "vkGetFenceStatus");
}

namespace {
detail::Ref<detail::SemaphoreState> make_semaphore(const Device& device, SemaphoreType type, std::uint64_t initial) {
    VkSemaphoreTypeCreateInfo type_info{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
    type_info.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
    type_info.initialValue = initial;
    VkSemaphoreCreateInfo ci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    if (type == SemaphoreType::timeline) ci.pNext = &type_info;
    auto s = detail::created_state<detail::SemaphoreState, &DeviceFunctions::vkCreateSemaphore>(device, ci,
                                                                                                "vkCreateSemaphore");
    s->type = type;
    return s;
}
}  // namespace

Semaphore Semaphore::create_binary(const Device& device) {
    detail::Caller("vkrc::Semaphore::create_binary").require_handle(device, "the Device");
    return Semaphore(make_semaphore(device, SemaphoreType::binary, 0));
}

Semaphore Semaphore::create_timeline(const Device& device, std::uint64_t initial_value) {
    detail::Caller("vkrc::Semaphore::create_timeline").require_handle(device, "the Device");
    return Semaphore(make_semaphore(device, SemaphoreType::timeline, initial_value));
}

Semaphore Semaphore::adopt(const Device& device, VkSemaphore semaphore, SemaphoreType type, Ownership ownership) {
    auto s = detail::adopted_state<detail::SemaphoreState>(detail::Caller{"vkrc::Semaphore::adopt"}, device,
                                                           "the Device", semaphore, "VkSemaphore", ownership);
    s->type = type;
    return Semaphore(std::move(s));
}

namespace {
void require_timeline(const detail::Caller& caller, const Semaphore& s) {
    caller.require(s.type() == SemaphoreType::timeline, "the semaphore is binary, not timeline");
}
}  // namespace

std::uint64_t Semaphore::value() const {
    require_timeline(detail::Caller{"vkrc::Semaphore::value"}, *this);
    const auto& d = state_->device;
    std::uint64_t v = 0;
    d.state()->finish_call(d.fn().vkGetSemaphoreCounterValue(d.vk(), state_->handle, &v), "vkGetSemaphoreCounterValue");
    return v;
}

void Semaphore::signal(std::uint64_t value) const {
    require_timeline(detail::Caller{"vkrc::Semaphore::signal"}, *this);
    const auto& d = state_->device;
    VkSemaphoreSignalInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_SIGNAL_INFO};
    info.semaphore = state_->handle;
    info.value = value;
    check(d.fn().vkSignalSemaphore(d.vk(), &info), "vkSignalSemaphore");
}

VkResult Semaphore::wait(std::uint64_t value, std::uint64_t timeout_ns) const {
    require_timeline(detail::Caller{"vkrc::Semaphore::wait"}, *this);
    const auto& d = state_->device;
    VkSemaphoreWaitInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
    info.semaphoreCount = 1;
    info.pSemaphores = &state_->handle;
    info.pValues = &value;
    return d.state()->finish_call(d.fn().vkWaitSemaphores(d.vk(), &info, timeout_ns), "vkWaitSemaphores");
}

Event Event::create(const Device& device, bool device_only) {
    detail::Caller("vkrc::Event::create").require_handle(device, "the Device");
    VkEventCreateInfo ci{VK_STRUCTURE_TYPE_EVENT_CREATE_INFO};
    if (device_only) ci.flags = VK_EVENT_CREATE_DEVICE_ONLY_BIT;
    return Event(
        detail::created_state<detail::EventState, &DeviceFunctions::vkCreateEvent>(device, ci, "vkCreateEvent"));
}

Event Event::adopt(const Device& device, VkEvent event, Ownership ownership) {
    return Event(detail::adopted_state<detail::EventState>(detail::Caller{"vkrc::Event::adopt"}, device, "the Device",
                                                           event, "VkEvent", ownership));
}

void Event::set() const {
    const auto& d = state_->device;
    check(d.fn().vkSetEvent(d.vk(), state_->handle), "vkSetEvent");
}
void Event::unset() const {
    const auto& d = state_->device;
    check(d.fn().vkResetEvent(d.vk(), state_->handle), "vkResetEvent");
}
VkResult Event::status() const {
    const auto& d = state_->device;
    return d.state()->check_result(d.fn().vkGetEventStatus(d.vk(), state_->handle), "vkGetEventStatus");
}

namespace {
// The state of a pool described by info, its VkQueryPool not yet set.
detail::Ref<detail::QueryPoolState> query_pool_state(const detail::Caller& caller, const Device& device,
                                                     const QueryPoolCreateInfo& info) {
    caller.require_handle(device, "the Device");
    caller.require(info.query_count != 0, "query_count is 0");
    const bool statistics = info.query_type == VK_QUERY_TYPE_PIPELINE_STATISTICS;
    caller.require(!statistics || info.pipeline_statistics != 0,
                   "a PIPELINE_STATISTICS pool with no pipeline_statistics flags");
    detail::Ref<detail::QueryPoolState> s(new detail::QueryPoolState);
    s->device = device;
    s->count = info.query_count;
    s->type = info.query_type;
    s->values_per_query = statistics ? static_cast<std::uint32_t>(std::popcount(info.pipeline_statistics)) : 1;
    return s;
}
}  // namespace

QueryPool QueryPool::adopt(const Device& device, VkQueryPool pool, const QueryPoolCreateInfo& info,
                           Ownership ownership) {
    const detail::Caller caller{"vkrc::QueryPool::adopt"};
    auto s = query_pool_state(caller, device, info);
    caller.require_not_null(pool, "VkQueryPool");
    s->handle = pool;
    s->ownership = ownership;
    return QueryPool(std::move(s));
}

QueryPool QueryPool::create(const Device& device, const QueryPoolCreateInfo& info) {
    auto s = query_pool_state(detail::Caller{"vkrc::QueryPool::create"}, device, info);
    VkQueryPoolCreateInfo ci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    ci.pNext = info.next;
    ci.queryType = info.query_type;
    ci.queryCount = info.query_count;
    ci.pipelineStatistics = info.pipeline_statistics;
    check(device.fn().vkCreateQueryPool(device.vk(), &ci, nullptr, &s->handle), "vkCreateQueryPool");
    return QueryPool(std::move(s));
}

VkResult QueryPool::results(std::uint32_t first_query, Span<std::uint64_t> out, VkQueryResultFlags flags) const {
    const detail::Caller caller{"vkrc::QueryPool::results"};
    caller.require_handle(*this, "the QueryPool");
    const std::uint32_t words = words_per_query(flags);
    caller.require(!out.empty() && out.size() % words == 0, "out holds ", out.size(), " values, not a multiple of the ",
                   words, " per query (values_per_query() ", state_->values_per_query,
                   ", plus one for WITH_AVAILABILITY or WITH_STATUS_KHR)");
    const std::size_t count = out.size() / words;
    caller.require(first_query <= state_->count && count <= state_->count - first_query, "queries ", first_query, "+",
                   count, " exceed the pool's ", state_->count);
    const auto& d = state_->device;
    VkResult r = d.fn().vkGetQueryPoolResults(d.vk(), state_->handle, first_query, static_cast<std::uint32_t>(count),
                                              out.size_bytes(), out.data(), words * sizeof(std::uint64_t),
                                              flags | VK_QUERY_RESULT_64_BIT);
    return d.state()->finish_call(r, "vkGetQueryPoolResults");
}

std::uint32_t QueryPool::words_per_query(VkQueryResultFlags flags) const VKRC_UNCHECKED_NOEXCEPT {
    const bool extra = flags & (VK_QUERY_RESULT_WITH_AVAILABILITY_BIT | VK_QUERY_RESULT_WITH_STATUS_BIT_KHR);
    return live("vkrc::QueryPool::words_per_query").values_per_query + (extra ? 1 : 0);
}

double QueryPool::timestamp_period_ns() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::QueryPool::timestamp_period_ns").device.physical_device().properties().limits.timestampPeriod;
}

VKRC_END_NAMESPACE
