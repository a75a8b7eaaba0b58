#include "vkrc/device.hpp"
#include "vkrc/memory.hpp"  // DeviceAllocator, for the state's allocator references

#include <algorithm>
#include <atomic>  // std::memory_order for detail::Atomic
#include <cstring>
#include <string>

VKRC_BEGIN_NAMESPACE

namespace detail {

DeviceState::~DeviceState() {
    if (device == VK_NULL_HANDLE) return;
    // Every handle is gone; whatever the GPU still runs must finish before
    // the queued destructions. A lost device returns at once.
    VkResult idle = fn.vkDeviceWaitIdle(device);
    if (idle == VK_ERROR_DEVICE_LOST) mark_lost();
    if (idle != VK_SUCCESS && !lost.load(std::memory_order_relaxed)) {
        // Out of memory while waiting: vkrc's own timelines still say when
        // its submissions are done.
        for (auto& q : queues) {
            std::uint64_t value = q.submitted.load(std::memory_order_acquire);
            VkSemaphoreWaitInfo wait{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
            wait.semaphoreCount = 1;
            wait.pSemaphores = &q.timeline;
            wait.pValues = &value;
            fn.vkWaitSemaphores(device, &wait, UINT64_MAX);
        }
    }
    for (auto& batch : deferred_) {
        for (auto& action : batch.actions) action.run(*this, action.handle, action.context);
    }
    deferred_.clear();
    release_allocators();
    for (auto& q : queues) {
        if (q.timeline != VK_NULL_HANDLE) fn.vkDestroySemaphore(device, q.timeline, nullptr);
    }
    if (ownership == Ownership::owned) fn.vkDestroyDevice(device, nullptr);
}

bool DeviceState::idle_now() noexcept {
    bool idle = true;
    for (auto& q : queues) {
        std::uint64_t submitted = q.submitted.load(std::memory_order_acquire);
        if (q.completed.load(std::memory_order_relaxed) >= submitted) continue;
        std::uint64_t value = 0;
        VkResult r = fn.vkGetSemaphoreCounterValue(device, q.timeline, &value);
        if (r == VK_ERROR_DEVICE_LOST) mark_lost();
        if (r == VK_SUCCESS) {
            // Keep the cache monotonic when several threads refresh it.
            std::uint64_t seen = q.completed.load(std::memory_order_relaxed);
            while (seen < value && !q.completed.compare_exchange_weak(seen, value, std::memory_order_relaxed)) {
            }
        }
        if (value < submitted) idle = false;
    }
    return idle || lost.load(std::memory_order_relaxed);
}

void DeviceState::destroy_after_gpu(DeferredAction action) noexcept {
    std::vector<DeferredAction> ready;
    bool run_now = false;
    {
        LockGuard lock(deferred_mutex_);
        if (deferred_.empty() && idle_now()) {
            run_now = true;
        } else {
            bool queued = false;
            try {
                // Needs the values of work submitted so far; a batch queued
                // while the same work was pending is shared.
                std::vector<std::uint64_t> values;
                values.reserve(queues.size());
                for (auto& q : queues) values.push_back(q.submitted.load(std::memory_order_acquire));
                if (deferred_.empty() || deferred_.back().wait_values != values) {
                    deferred_.push_back(Batch{std::move(values), {}});
                }
                deferred_.back().actions.push_back(action);
                ++deferred_actions_;
                queued = true;
                take_ready(ready);
            } catch (...) {
                // Out of host memory. Unqueued, waiting is the only safe way
                // left to destroy the object; queued, it runs on a later collect.
                if (!queued) {
                    fn.vkDeviceWaitIdle(device);
                    run_now = true;
                }
            }
        }
    }
    if (run_now) action.run(*this, action.handle, action.context);
    for (auto& a : ready) a.run(*this, a.handle, a.context);
}

void DeviceState::take_ready(std::vector<DeferredAction>& out) {
    if (deferred_.empty()) return;
    bool all = idle_now();
    std::size_t batches = 0;
    std::size_t actions = 0;
    for (const auto& batch : deferred_) {
        bool done = all;
        if (!done) {
            done = true;
            for (std::size_t i = 0; i < queues.size(); ++i) {
                if (queues[i].completed.load(std::memory_order_relaxed) < batch.wait_values[i]) done = false;
            }
        }
        if (!done) break;
        ++batches;
        actions += batch.actions.size();
    }
    // The only allocation comes first, so a failure leaves the queue as it was.
    out.reserve(out.size() + actions);
    for (; batches > 0; --batches) {
        auto& batch = deferred_.front();
        out.insert(out.end(), batch.actions.begin(), batch.actions.end());
        deferred_actions_ -= batch.actions.size();
        deferred_.pop_front();
    }
}

void DeviceState::collect() noexcept {
    std::vector<DeferredAction> ready;
    {
        LockGuard lock(deferred_mutex_);
        if (deferred_.empty()) return;
        try {
            take_ready(ready);
        } catch (...) {
            return;  // out of host memory: the actions stay queued for a later collect
        }
    }
    for (auto& a : ready) a.run(*this, a.handle, a.context);
}

void DeviceState::submitted_snapshot(std::vector<std::uint64_t>& out) const {
    out.resize(queues.size());
    for (std::size_t i = 0; i < queues.size(); ++i) out[i] = queues[i].submitted.load(std::memory_order_acquire);
}

bool DeviceState::reached(std::span<const std::uint64_t> snapshot) noexcept {
    if (lost.load(std::memory_order_relaxed)) return true;
    for (std::size_t i = 0; i < snapshot.size() && i < queues.size(); ++i) {
        auto& q = queues[i];
        if (q.completed.load(std::memory_order_relaxed) >= snapshot[i]) continue;
        std::uint64_t value = 0;
        VkResult r = fn.vkGetSemaphoreCounterValue(device, q.timeline, &value);
        if (r == VK_ERROR_DEVICE_LOST) {
            mark_lost();
            return true;
        }
        if (r != VK_SUCCESS) return false;
        std::uint64_t seen = q.completed.load(std::memory_order_relaxed);
        while (seen < value && !q.completed.compare_exchange_weak(seen, value, std::memory_order_relaxed)) {
        }
        if (value < snapshot[i]) return false;
    }
    return true;
}

std::size_t DeviceState::deferred_count() const noexcept {
    LockGuard lock(deferred_mutex_);
    return deferred_actions_;
}

}  // namespace detail

namespace {

// For failure paths before the device's function table exists.
void destroy_raw_device(const PhysicalDevice& physical, VkDevice raw) noexcept {
    auto destroy = reinterpret_cast<PFN_vkDestroyDevice>(physical.fn().vkGetDeviceProcAddr(raw, "vkDestroyDevice"));
    if (destroy) destroy(raw, nullptr);
}

void init_queues(detail::DeviceState& s, std::span<const QueueRequest> requests) {
    VkSemaphoreTypeCreateInfo type{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
    type.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
    VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, &type};
    for (const auto& request : requests) {
        for (std::uint32_t i = 0; i < request.queue_priorities.size(); ++i) {
            auto& q = s.queues.emplace_back();
            q.family_index = request.queue_family_index;
            q.index = i;
            s.fn.vkGetDeviceQueue(s.device, request.queue_family_index, i, &q.queue);
            check(s.fn.vkCreateSemaphore(s.device, &info, nullptr, &q.timeline), "vkCreateSemaphore");
        }
    }
}

void make_device(const PhysicalDevice& physical, VkDevice raw, Ownership ownership,
                   std::span<const QueueRequest> queues, std::span<const char* const> extensions,
                   detail::Ref<detail::DeviceState>& state) {
    state = detail::Ref<detail::DeviceState>(new detail::DeviceState);
    auto& s = *state;
    s.device = raw;
    s.ownership = ownership;
    s.physical_device = physical;
    s.fn = DeviceFunctions::load(physical.fn().vkGetDeviceProcAddr, raw);
    s.enabled_extensions.assign(extensions.begin(), extensions.end());
    init_queues(s, queues);
}

}  // namespace

Device Device::create(const PhysicalDevice& physical) { return create(physical, DeviceCreateInfo{}); }

Device Device::create(const PhysicalDevice& physical, const DeviceCreateInfo& info) {
    if (!physical) throw UsageError("vkrc::Device::create: the PhysicalDevice handle is empty");
    std::vector<QueueRequest> requests = info.queue_requests;
    if (requests.empty()) {
        int family = physical.find_queue_family(VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT);
        if (family < 0) throw UsageError("vkrc::Device::create: no queue family with graphics and compute");
        requests.push_back(QueueRequest{static_cast<std::uint32_t>(family)});
    }
    std::vector<VkDeviceQueueCreateInfo> queue_infos;
    for (const auto& r : requests) {
        if (r.queue_family_index >= physical.queue_families().size()) {
            throw UsageError("vkrc::Device::create: queue family " + std::to_string(r.queue_family_index) +
                             " does not exist (the device has " +
                             std::to_string(physical.queue_families().size()) + ")");
        }
        if (r.queue_priorities.empty() ||
            r.queue_priorities.size() > physical.queue_families()[r.queue_family_index].queueCount) {
            throw UsageError("vkrc::Device::create: queue family " + std::to_string(r.queue_family_index) +
                             " has " + std::to_string(physical.queue_families()[r.queue_family_index].queueCount) +
                             " queues; asked for " + std::to_string(r.queue_priorities.size()));
        }
        VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
        q.queueFamilyIndex = r.queue_family_index;
        q.queueCount = static_cast<std::uint32_t>(r.queue_priorities.size());
        q.pQueuePriorities = r.queue_priorities.data();
        queue_infos.push_back(q);
    }

    std::vector<const char*> extensions = info.enabled_extension_names;
    if (info.enable_memory_budget && physical.supports_extension(VK_EXT_MEMORY_BUDGET_EXTENSION_NAME) &&
        std::none_of(extensions.begin(), extensions.end(),
                     [](const char* e) { return std::strcmp(e, VK_EXT_MEMORY_BUDGET_EXTENSION_NAME) == 0; })) {
        extensions.push_back(VK_EXT_MEMORY_BUDGET_EXTENSION_NAME);
    }

    auto f13 = info.vulkan13_features;
    f13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
    f13.pNext = const_cast<void*>(info.next);
    f13.synchronization2 = VK_TRUE;
    f13.dynamicRendering = VK_TRUE;
    // Required of every 1.3 device; SPIR-V for vulkan1.3 (vkrc_add_shaders) uses LocalSizeId.
    f13.maintenance4 = VK_TRUE;
    auto f12 = info.vulkan12_features;
    f12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
    f12.pNext = &f13;
    f12.timelineSemaphore = VK_TRUE;
    auto f11 = info.vulkan11_features;
    f11.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES;
    f11.pNext = &f12;
    VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f11};
    features.features = info.enabled_features;

    VkDeviceCreateInfo create{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &features};
    create.queueCreateInfoCount = static_cast<std::uint32_t>(queue_infos.size());
    create.pQueueCreateInfos = queue_infos.data();
    create.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
    create.ppEnabledExtensionNames = extensions.data();

    VkDevice raw = VK_NULL_HANDLE;
    check(physical.fn().vkCreateDevice(physical.vk(), &create, nullptr, &raw), "vkCreateDevice");
    detail::Ref<detail::DeviceState> state;
    try {
        make_device(physical, raw, Ownership::owned, requests, extensions, state);
    } catch (...) {
        if (!state) destroy_raw_device(physical, raw);
        throw;  // otherwise the state's destructor destroyed the device
    }
    return Device(std::move(state));
}

Device Device::adopt(const PhysicalDevice& physical, VkDevice raw, Ownership ownership,
                     std::span<const QueueRequest> queues, std::span<const char* const> enabled_extensions) {
    if (!physical) throw UsageError("vkrc::Device::adopt: the PhysicalDevice handle is empty");
    if (raw == VK_NULL_HANDLE) throw UsageError("vkrc::Device::adopt: the VkDevice is VK_NULL_HANDLE");
    detail::Ref<detail::DeviceState> state;
    try {
        make_device(physical, raw, ownership, queues, enabled_extensions, state);
    } catch (...) {
        if (!state && ownership == Ownership::owned) destroy_raw_device(physical, raw);
        throw;
    }
    return Device(std::move(state));
}

bool Device::extension_enabled(const char* name) const noexcept {
    const auto& e = state_->enabled_extensions;
    return std::find(e.begin(), e.end(), name) != e.end();
}

Queue Device::queue(std::uint32_t family_index, std::uint32_t index) const {
    for (auto& q : state_->queues) {
        if (q.family_index == family_index && q.index == index) return Queue(*this, &q);
    }
    throw UsageError("vkrc::Device::queue: queue " + std::to_string(index) + " of family " +
                     std::to_string(family_index) + " was not requested when the device was created");
}

Queue Device::default_queue() const {
    if (state_->queues.empty()) throw UsageError("vkrc::Device::default_queue: the device has no queues");
    return Queue(*this, &state_->queues.front());
}

void Device::wait_idle() const {
    VkResult r = fn().vkDeviceWaitIdle(vk());
    if (r == VK_ERROR_DEVICE_LOST) state_->mark_lost();
    state_->collect();
    check(r, "vkDeviceWaitIdle");
}

void Device::collect_garbage() const noexcept { state_->collect(); }
std::size_t Device::deferred_count() const noexcept { return state_->deferred_count(); }
bool Device::lost() const noexcept { return state_->lost.load(std::memory_order_relaxed); }

void Queue::submit(std::span<const VkSubmitInfo2> submits, VkFence fence) const {
    auto& q = *queue_;
    auto& d = *device_.state();
    VkResult r;
    {
        LockGuard lock(q.mutex);
        const std::uint64_t value = q.submitted.load(std::memory_order_relaxed) + 1;
        VkSemaphoreSubmitInfo timeline{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
        timeline.semaphore = q.timeline;
        timeline.value = value;
        timeline.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
        // The timeline signal goes into the last batch when it has room on
        // the stack; otherwise into one more batch, which submission order
        // still places after all the work before it.
        constexpr std::uint32_t inline_signals = 8;
        VkSemaphoreSubmitInfo signals[inline_signals + 1];
        VkSubmitInfo2 tail[2];
        std::uint32_t tail_count = 0;
        std::size_t head = submits.size();
        if (!submits.empty() && submits.back().signalSemaphoreInfoCount <= inline_signals) {
            head = submits.size() - 1;
            tail[0] = submits.back();
            if (tail[0].signalSemaphoreInfoCount) {
                std::memcpy(signals, tail[0].pSignalSemaphoreInfos,
                            tail[0].signalSemaphoreInfoCount * sizeof(VkSemaphoreSubmitInfo));
            }
            signals[tail[0].signalSemaphoreInfoCount] = timeline;
            tail[0].signalSemaphoreInfoCount += 1;
            tail[0].pSignalSemaphoreInfos = signals;
            tail_count = 1;
        } else {
            tail[0] = VkSubmitInfo2{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
            tail[0].signalSemaphoreInfoCount = 1;
            tail[0].pSignalSemaphoreInfos = &timeline;
            tail_count = 1;
        }
        r = VK_SUCCESS;
        if (head > 0) r = d.fn.vkQueueSubmit2(q.queue, static_cast<std::uint32_t>(head), submits.data(), VK_NULL_HANDLE);
        if (r == VK_SUCCESS) r = d.fn.vkQueueSubmit2(q.queue, tail_count, tail, fence);
        if (r == VK_SUCCESS) q.submitted.store(value, std::memory_order_release);
    }
    if (r == VK_ERROR_DEVICE_LOST) d.mark_lost();
    d.collect();
    check(r, "vkQueueSubmit2");
}

void Queue::wait_idle() const {
    VkResult r;
    {
        LockGuard lock(queue_->mutex);
        r = device_.fn().vkQueueWaitIdle(queue_->queue);
    }
    if (r == VK_ERROR_DEVICE_LOST) device_.state()->mark_lost();
    device_.state()->collect();
    check(r, "vkQueueWaitIdle");
}

VKRC_END_NAMESPACE
