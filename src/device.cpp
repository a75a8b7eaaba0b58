#include "vkrc/device.hpp"

#include "text.hpp"
#include "object_state.hpp"
#include "vkrc/extension_functions.hpp"

#include <algorithm>
#include <atomic>  // std::memory_order for detail::Atomic
#include <cstring>
#include <string>
#include <vector>

VKRC_BEGIN_NAMESPACE

int find_dedicated_queue_family(const PhysicalDevice& physical, QueueRole role) {
    detail::Caller("vkrc::find_dedicated_queue_family").require_handle(physical, "the PhysicalDevice");
    constexpr VkQueueFlags graphics = VK_QUEUE_GRAPHICS_BIT, compute = VK_QUEUE_COMPUTE_BIT;
    const auto& families = physical.queue_families();
    for (std::uint32_t i = 0; i < families.size(); ++i) {
        const VkQueueFlags f = families[i].queueFlags;
        const bool match = role == QueueRole::graphics  ? (f & (graphics | compute)) == (graphics | compute)
                           : role == QueueRole::compute ? (f & compute) && !(f & graphics)
                                                        : (f & VK_QUEUE_TRANSFER_BIT) && !(f & (graphics | compute));
        if (match) return static_cast<int>(i);
    }
    return -1;
}

namespace detail {

DeviceState::~DeviceState() {
    delete ext_fn.load(__ATOMIC_ACQUIRE);
    if (device == VK_NULL_HANDLE) return;
    // Every handle is gone; whatever the GPU still runs must finish before
    // the queued destructions. A lost device returns at once.
    VkResult idle = note_result(fn.vkDeviceWaitIdle(device));
    if (idle != VK_SUCCESS && !lost.load(std::memory_order_relaxed)) {
        // Out of memory while waiting: vkrc's own timelines still say when
        // its submissions are done.
        for (auto& q : queues) wait_for_submission(q, q.timeline.last_submitted());
    }
    // Children before what they were made from: held drops are older.
    deferred.run_all(*this);
    commands.run_all(*this);
    allocators.release_all(*this);
    for (auto& q : queues) {
        if (q.semaphore != VK_NULL_HANDLE) fn.vkDestroySemaphore(device, q.semaphore, nullptr);
    }
    if (ownership == Ownership::owned) fn.vkDestroyDevice(device, nullptr);
}

VkResult DeviceState::refresh(QueueState& q) noexcept {
    std::uint64_t value = 0;
    const VkResult r = note_result(fn.vkGetSemaphoreCounterValue(device, q.semaphore, &value));
    if (r == VK_SUCCESS) q.timeline.note_completed(value);
    return r;
}

std::uint64_t DeviceState::read_completed(QueueState& q) {
    check(refresh(q), "vkGetSemaphoreCounterValue");
    return q.timeline.completed();
}

bool DeviceState::idle_now() noexcept {
    bool idle = true;
    for (auto& q : queues) {
        const std::uint64_t last = q.timeline.last_submitted();
        if (q.timeline.completed() >= last) continue;
        // Without a signal covering the last submit, nothing says it has completed.
        if (q.timeline.last_signalled() < last || refresh(q) != VK_SUCCESS || q.timeline.completed() < last)
            idle = false;
    }
    return idle || lost.load(std::memory_order_relaxed);
}

VkResult DeviceState::wait_for_submission(QueueState& q, std::uint64_t number, const char** failed_call) noexcept {
    if (q.timeline.completed() >= number) return VK_SUCCESS;
    // Waits for a value some submit signals, at or after that submission (the
    // validation layer of 1.3.239 reports a timeout for values between signals).
    std::uint64_t value = q.timeline.last_signalled();
    if (value < number) {
        VkResult r = signal_submitted_work(q, value);
        if (r != VK_SUCCESS) {
            if (failed_call) *failed_call = "vkQueueSubmit2";
            return r;
        }
    }
    VkSemaphoreWaitInfo wait{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
    wait.semaphoreCount = 1;
    wait.pSemaphores = &q.semaphore;
    wait.pValues = &value;
    VkResult r = note_result(fn.vkWaitSemaphores(device, &wait, UINT64_MAX));
    if (r == VK_SUCCESS) q.timeline.note_completed(value);
    if (r != VK_SUCCESS && failed_call) *failed_call = "vkWaitSemaphores";
    return r;
}

void DeviceState::await(QueueState& q, std::uint64_t number) {
    const char* failed_call = nullptr;
    VkResult r = wait_for_submission(q, number, &failed_call);
    if (r != VK_SUCCESS) check(r, failed_call);
}

VkResult DeviceState::signal_submitted_work(QueueState& q, std::uint64_t& value) noexcept {
    LockGuard lock(q.mutex);
    const std::uint64_t number = q.timeline.next_number();
    value = q.timeline.last_signalled();
    if (value == number - 1) return VK_SUCCESS;
    const bool wanted = q.timeline.take_signal_request();
    VkSemaphoreSubmitInfo signal{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
    signal.semaphore = q.semaphore;
    signal.value = number;
    signal.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    submit.signalSemaphoreInfoCount = 1;
    submit.pSignalSemaphoreInfos = &signal;
    VkResult r = note_result(fn.vkQueueSubmit2(q.queue, 1, &submit, VK_NULL_HANDLE));
    if (r != VK_SUCCESS) {
        if (wanted) q.timeline.request_signal();
        return r;
    }
    value = number;
    q.timeline.note_signalled(number);
    return VK_SUCCESS;
}

void DeviceState::submitted_snapshot(List<std::uint64_t>& out) {
    out.resize(queues.size());
    for (std::size_t i = 0; i < queues.size(); ++i) out[i] = queues[i].timeline.covering_value();
}

bool DeviceState::reached(Span<const std::uint64_t> snapshot) noexcept {
    if (lost.load(std::memory_order_relaxed)) return true;
    for (std::size_t i = 0; i < snapshot.size() && i < queues.size(); ++i) {
        auto& q = queues[i];
        if (q.timeline.completed() >= snapshot[i]) continue;
        if (refresh(q) != VK_SUCCESS) return lost.load(std::memory_order_relaxed);
        if (q.timeline.completed() < snapshot[i]) return false;
    }
    return true;
}

// ---------------------------------------------------------------- DeferredDestructor

// ---------------------------------------------------------------- DeviceLink

DeviceLink::DeviceLink(const Device& device) noexcept : view_(device.state()) {
    if (DeviceState* s = device.state()) s->add_child();
}
DeviceLink::DeviceLink(DeviceLink&& other) noexcept : view_(other.view_.take()) {}
DeviceLink& DeviceLink::operator=(const Device& device) noexcept {
    DeviceState* s = device.state();
    if (s) s->add_child();  // first: device may be the one this link holds
    DeviceState* old = view_.take();
    view_.set(s);
    if (old) old->release_child();
    return *this;
}
DeviceLink::~DeviceLink() {
    if (DeviceState* s = view_.take()) s->release_child();
}

// ---------------------------------------------------------------- ChildCount

namespace {
// Far below any count: a stripe at or under it was drained (dead_credit: its
// value once drained; returns that still land there do not bring it near).
constexpr std::int64_t dead_credit = INT64_MIN / 2;
constexpr std::int64_t credit_batch = 64;  // taken from / given back to the total at once
bool is_dead(std::int64_t credits) noexcept { return credits < dead_credit / 2; }

// The calling thread's stripe: threads take them round-robin at their first child.
std::size_t thread_stripe(std::size_t count) noexcept {
    static Atomic<std::size_t> next{0};
    thread_local std::size_t mine = next.fetch_add(1, __ATOMIC_RELAXED);
    return mine % count;
}
}  // namespace

// A new reference comes from an existing one (a handle or a child), so the
// total cannot be at zero here, and increments need no order (as RefCounted's).
void ChildCount::add_striped() noexcept {
    auto& stripe = stripes_[thread_stripe(stripe_count)].credits;
    std::int64_t credits = stripe.load(__ATOMIC_RELAXED);
    while (credits > 0) {
        if (stripe.compare_exchange_weak(credits, credits - 1, __ATOMIC_RELAXED)) return;
    }
    if (is_dead(credits)) {
        total_.fetch_add(1, __ATOMIC_RELAXED);
        return;
    }
    // None left: a batch from the total, one for this reference.
    total_.fetch_add(credit_batch, __ATOMIC_RELAXED);
    if (is_dead(stripe.fetch_add(credit_batch - 1, __ATOMIC_RELAXED))) {
        total_.fetch_sub(credit_batch - 1, __ATOMIC_RELAXED);  // drained meanwhile: this one's stays
    }
}

// Acquire-release, as RefCounted's decrement: the thread that destroys the
// device sees every write made through the other references. Each path
// gives up this reference in its one last write (a return to a live stripe
// is counted by release_handles when it drains), after which another thread
// may destroy the device: nothing here touches it after that write.
bool ChildCount::release_striped() noexcept {
    auto& stripe = stripes_[thread_stripe(stripe_count)].credits;
    std::int64_t credits = stripe.load(__ATOMIC_RELAXED);
    for (;;) {
        if (is_dead(credits)) return total_.fetch_sub(1, __ATOMIC_ACQ_REL) == 1;
        // Past two batches, one goes back with this reference, so that a
        // thread that only drops holds few credits.
        const bool surplus = credits >= 2 * credit_batch;
        const std::int64_t next = surplus ? credits + 1 - credit_batch : credits + 1;
        if (stripe.compare_exchange_weak(credits, next, __ATOMIC_ACQ_REL)) {
            return surplus && total_.fetch_sub(credit_batch, __ATOMIC_ACQ_REL) == credit_batch;
        }
    }
}

bool ChildCount::release_handles() noexcept {
    std::int64_t drained = 0;
    if constexpr (ThreadPolicy::multi_thread) {
        for (auto& s : stripes_) {
            const std::int64_t credits = s.credits.exchange(dead_credit, __ATOMIC_ACQ_REL);
            if (!is_dead(credits)) drained += credits;
        }
    }
    return total_.fetch_sub(1 + drained, __ATOMIC_ACQ_REL) == 1 + drained;
}

void DeferredDestructor::destroy_after_gpu(DeviceState& device, DeferredAction action) noexcept {
    // Nothing queued and nothing pending: runs now without the lock, so
    // threads dropping objects at once do not queue behind each other.
    if (count_.load(__ATOMIC_ACQUIRE) == 0 && device.idle_now()) {
        action.run(device, action.handle, action.context);
        return;
    }
    List<DeferredAction> ready;
    bool run_now = false;
    {
        LockGuard lock(mutex_);
        if (batches_.empty() && device.idle_now()) {
            run_now = true;
        } else {
            bool queued = false;
            try {
                // Needs the values of work submitted so far; a batch queued
                // while the same work was pending is shared.
                List<std::uint64_t> values;
                device.submitted_snapshot(values);
                if (batches_.empty() || batches_.back().wait_values != values) {
                    batches_.push_back(Batch{std::move(values), {}});
                }
                batches_.back().actions.push_back(action);
                count_.fetch_add(1, std::memory_order_relaxed);
                queued = true;
                take_ready(device, ready);
            } catch (...) {
                // Out of host memory. Unqueued, waiting is the only safe way
                // left to destroy the object; queued, it runs on a later collect.
                if (!queued) {
                    device.fn.vkDeviceWaitIdle(device.device);
                    run_now = true;
                }
            }
        }
    }
    if (run_now) action.run(device, action.handle, action.context);
    for (auto& a : ready) a.run(device, a.handle, a.context);
}

void DeferredDestructor::take_ready(DeviceState& device, List<DeferredAction>& out) {
    if (batches_.empty()) return;
    const bool all = device.idle_now();
    auto done = [&](const Batch& batch) {
        for (std::size_t i = 0; i < device.queues.size(); ++i) {
            if (device.queues[i].timeline.completed() < batch.wait_values[i]) return false;
        }
        return true;
    };
    std::size_t batches = 0;
    std::size_t actions = 0;
    for (const auto& batch : batches_) {
        if (!all && !done(batch)) break;
        ++batches;
        actions += batch.actions.size();
    }
    // The only allocation comes first, so a failure leaves the queue as it was.
    out.reserve(out.size() + actions);
    for (std::size_t i = 0; i < batches; ++i) {
        const auto& batch = batches_[i];
        out.append(batch.actions.data(), batch.actions.size());
    }
    count_.fetch_sub(actions, std::memory_order_relaxed);
    batches_.erase_front(batches);
}

void DeferredDestructor::collect_queued(DeviceState& device) noexcept {
    List<DeferredAction> ready;
    {
        LockGuard lock(mutex_);
        if (batches_.empty()) return;
        try {
            take_ready(device, ready);
        } catch (...) {
            return;  // out of host memory: the actions stay queued for a later collect
        }
    }
    for (auto& a : ready) a.run(device, a.handle, a.context);
}

void DeferredDestructor::run_all(DeviceState& device) noexcept {
    for (auto& batch : batches_) {
        for (auto& action : batch.actions) action.run(device, action.handle, action.context);
    }
    batches_.clear();
    count_.store(0, std::memory_order_relaxed);
}

std::size_t DeferredDestructor::size() const noexcept {
    LockGuard lock(mutex_);
    return count_.load(std::memory_order_relaxed);
}

}  // namespace detail

namespace {

// For failure paths before the device's function table exists.
void destroy_raw_device(const PhysicalDevice& physical, VkDevice raw) noexcept {
    auto destroy = reinterpret_cast<PFN_vkDestroyDevice>(physical.fn().vkGetDeviceProcAddr(raw, "vkDestroyDevice"));
    if (destroy) destroy(raw, nullptr);
}

void init_queues(detail::DeviceState& s, Span<const QueueRequest> requests) {
    VkSemaphoreTypeCreateInfo type{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
    type.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
    VkSemaphoreCreateInfo ci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, &type};
    std::size_t count = 0;
    for (const auto& request : requests) count += request.queue_priorities.size();
    s.queues = List<detail::QueueState>(count);  // in place: QueueState does not move
    std::size_t next = 0;
    for (const auto& request : requests) {
        for (std::uint32_t i = 0; i < request.queue_priorities.size(); ++i) {
            auto& q = s.queues[next++];
            q.family_index = request.queue_family_index;
            q.index = i;
            s.fn.vkGetDeviceQueue(s.device, request.queue_family_index, i, &q.queue);
            check(s.fn.vkCreateSemaphore(s.device, &ci, nullptr, &q.semaphore), "vkCreateSemaphore");
        }
    }
}

// The loader hands out debug-utils entry points even when the instance did
// not enable the extension; calling them then is undefined, so they are
// dropped and the label methods (which test for null) become no-ops.
void drop_unless_debug_utils(const PhysicalDevice& physical, DeviceFunctions& fn) {
    if (physical.instance().extension_enabled(VK_EXT_DEBUG_UTILS_EXTENSION_NAME)) return;
    fn.vkSetDebugUtilsObjectNameEXT = nullptr;
    fn.vkSetDebugUtilsObjectTagEXT = nullptr;
    fn.vkQueueBeginDebugUtilsLabelEXT = nullptr;
    fn.vkQueueEndDebugUtilsLabelEXT = nullptr;
    fn.vkQueueInsertDebugUtilsLabelEXT = nullptr;
    fn.vkCmdBeginDebugUtilsLabelEXT = nullptr;
    fn.vkCmdEndDebugUtilsLabelEXT = nullptr;
    fn.vkCmdInsertDebugUtilsLabelEXT = nullptr;
}

bool family_has(const PhysicalDevice& physical, std::uint32_t family, VkQueueFlags flags) {
    return (physical.queue_families()[family].queueFlags & flags) == flags;
}

// Graphics and compute queues can also run transfers (the spec's rule).
bool family_can_do(const PhysicalDevice& physical, std::uint32_t family, QueueRole role) {
    switch (role) {
        case QueueRole::graphics: return family_has(physical, family, VK_QUEUE_GRAPHICS_BIT);
        case QueueRole::compute: return family_has(physical, family, VK_QUEUE_COMPUTE_BIT);
        case QueueRole::transfer:
            return (physical.queue_families()[family].queueFlags &
                    (VK_QUEUE_TRANSFER_BIT | VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) != 0;
    }
    return false;
}

// The first queue of the dedicated family, else the first other than those
// in taken that can do the role's work, else taken[0] (the graphics queue).
std::size_t pick_role_queue(const detail::DeviceState& s, QueueRole role, Span<const std::size_t> taken) {
    const int dedicated = find_dedicated_queue_family(s.physical_device, role);
    for (std::size_t i = 0; i < s.queues.size(); ++i) {
        if (static_cast<int>(s.queues[i].family_index) == dedicated) return i;
    }
    for (std::size_t i = 0; i < s.queues.size(); ++i) {
        if (std::find(taken.begin(), taken.end(), i) != taken.end()) continue;
        if (family_can_do(s.physical_device, s.queues[i].family_index, role)) return i;
    }
    return taken[0];
}

void assign_roles(detail::DeviceState& s) {
    if (s.queues.empty()) return;
    auto& graphics = s.role_queues[static_cast<int>(QueueRole::graphics)];
    for (graphics = 0; graphics < s.queues.size(); ++graphics) {
        if (family_can_do(s.physical_device, s.queues[graphics].family_index, QueueRole::graphics)) break;
    }
    if (graphics == s.queues.size()) graphics = 0;
    auto& transfer = s.role_queues[static_cast<int>(QueueRole::transfer)];
    const std::size_t after_graphics[] = {graphics};
    transfer = pick_role_queue(s, QueueRole::transfer, after_graphics);
    const std::size_t after_transfer[] = {graphics, transfer};
    s.role_queues[static_cast<int>(QueueRole::compute)] = pick_role_queue(s, QueueRole::compute, after_transfer);
}

// The default request, and those of the roles asked for: a dedicated family
// when there is one, else another queue of the graphics family if it has room.
void add_role_requests(const detail::Caller& caller, const PhysicalDevice& physical, const DeviceCreateInfo& info,
                       std::vector<QueueRequest>& requests) {
    // The family select() chose (one that presents, when it was given a
    // surface), else the first with graphics and compute.
    int graphics = physical.default_queue_family();
    if (graphics < 0 ||
        !family_has(physical, static_cast<std::uint32_t>(graphics), VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT))
        graphics = find_dedicated_queue_family(physical, QueueRole::graphics);
    caller.require(graphics >= 0, "no queue family with graphics and compute");
    requests.push_back(QueueRequest{static_cast<std::uint32_t>(graphics)});
    for (QueueRole role : {QueueRole::transfer, QueueRole::compute}) {
        if (!(role == QueueRole::transfer ? info.transfer_queue : info.compute_queue)) continue;
        const int family = find_dedicated_queue_family(physical, role);
        if (family >= 0) {
            requests.push_back(QueueRequest{static_cast<std::uint32_t>(family)});
        } else if (requests[0].queue_priorities.size() < physical.queue_families()[graphics].queueCount) {
            requests[0].queue_priorities.push_back(1.0f);
        }
    }
}

// Throws UsageError unless the physical device has request's family and that many queues in it.
void check_queue_request(const detail::Caller& caller, const PhysicalDevice& physical, const QueueRequest& r) {
    const auto& families = physical.queue_families();
    caller.require(r.queue_family_index < families.size(), "queue family ", r.queue_family_index,
                   " does not exist (the device has ", families.size(), ")");
    const std::uint32_t available = families[r.queue_family_index].queueCount;
    caller.require(!r.queue_priorities.empty() && r.queue_priorities.size() <= available, "queue family ",
                   r.queue_family_index, " has ", available, " queues; asked for ", r.queue_priorities.size());
}

// The create infos of the checked requests; they point into requests.
std::vector<VkDeviceQueueCreateInfo> queue_create_infos(const detail::Caller& caller, const PhysicalDevice& physical,
                                                        const std::vector<QueueRequest>& requests) {
    std::vector<VkDeviceQueueCreateInfo> infos;
    for (const auto& r : requests) {
        check_queue_request(caller, physical, r);
        VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
        q.pNext = r.next;
        q.queueFamilyIndex = r.queue_family_index;
        q.queueCount = static_cast<std::uint32_t>(r.queue_priorities.size());
        q.pQueuePriorities = r.queue_priorities.data();
        infos.push_back(q);
    }
    return infos;
}

// Whether info sets any of VK_EXT_mesh_shader's features.
bool wants_mesh_shader(const DeviceCreateInfo& info) {
    const auto& f = info.mesh_shader_features;
    return f.taskShader || f.meshShader || f.multiviewMeshShader || f.primitiveFragmentShadingRateMeshShader ||
           f.meshShaderQueries;
}
// Whether info asks for any VK_KHR_acceleration_structure or VK_KHR_ray_query feature.
bool wants_acceleration_structure(const DeviceCreateInfo& info) {
    const auto& a = info.acceleration_structure_features;
    return a.accelerationStructure || a.accelerationStructureCaptureReplay || a.accelerationStructureIndirectBuild ||
           a.accelerationStructureHostCommands || a.descriptorBindingAccelerationStructureUpdateAfterBind;
}
bool wants_ray_query(const DeviceCreateInfo& info) { return info.ray_query_features.rayQuery != VK_FALSE; }
// Whether info asks for any VK_KHR_ray_tracing_pipeline feature.
bool wants_ray_tracing_pipeline(const DeviceCreateInfo& info) {
    const auto& r = info.ray_tracing_pipeline_features;
    return r.rayTracingPipeline || r.rayTracingPipelineShaderGroupHandleCaptureReplay ||
           r.rayTracingPipelineShaderGroupHandleCaptureReplayMixed || r.rayTracingPipelineTraceRaysIndirect ||
           r.rayTraversalPrimitiveCulling;
}

// The extensions asked for, those the features asked for need, and those
// vkrc enables where the device has them.
std::vector<const char*> device_extensions(const PhysicalDevice& physical, const DeviceCreateInfo& info) {
    std::vector<const char*> extensions(info.enabled_extension_names.begin(), info.enabled_extension_names.end());
    if (wants_mesh_shader(info)) detail::add_unique(extensions, VK_EXT_MESH_SHADER_EXTENSION_NAME);
    // VK_KHR_ray_tracing_pipeline depends on VK_KHR_acceleration_structure.
    if (wants_acceleration_structure(info) || wants_ray_tracing_pipeline(info)) {
        detail::add_unique(extensions, VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME);
        detail::add_unique(extensions, VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME);
    }
    if (wants_ray_query(info)) detail::add_unique(extensions, VK_KHR_RAY_QUERY_EXTENSION_NAME);
    if (wants_ray_tracing_pipeline(info)) detail::add_unique(extensions, VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME);
    if (info.enable_memory_budget && physical.supports_extension(VK_EXT_MEMORY_BUDGET_EXTENSION_NAME)) {
        detail::add_unique(extensions, VK_EXT_MEMORY_BUDGET_EXTENSION_NAME);
    }
    // The spec requires it enabled wherever it is offered (portability drivers).
    if (physical.supports_extension("VK_KHR_portability_subset")) {
        detail::add_unique(extensions, "VK_KHR_portability_subset");
    }
    return extensions;
}

// Puts an extension's feature struct at the head of chain when it is wanted.
template <class Features>
void chain_if(bool wanted, Features& features, void*& chain) {
    if (!wanted) return;
    features.pNext = chain;
    chain = &features;
}

// features, given features: the user's struct with its sType and an
// empty pNext kept (a caller's struct may have neither set).
template <class Features>
void copy_features(Features& features, const Features& given) {
    const VkStructureType type = features.sType;
    features = given;
    features.sType = type;
    features.pNext = nullptr;
}

// The features asked for, plus those vkrc needs, chained for vkCreateDevice.
// Its members point at each other, so it is made in place and never copied.
struct FeatureChain {
    explicit FeatureChain(const DeviceCreateInfo& info) {
        copy_features(chained.vulkan11, info.vulkan11_features);
        copy_features(chained.vulkan12, info.vulkan12_features);
        copy_features(chained.vulkan13, info.vulkan13_features);
        copy_features(chained.mesh_shader, info.mesh_shader_features);
        copy_features(chained.acceleration_structure, info.acceleration_structure_features);
        copy_features(chained.ray_query, info.ray_query_features);
        copy_features(chained.ray_tracing_pipeline, info.ray_tracing_pipeline_features);
        chained.vulkan13.synchronization2 = VK_TRUE;
        chained.vulkan13.dynamicRendering = VK_TRUE;
        // Required of every 1.3 device; SPIR-V for vulkan1.3 (vkrc_add_shaders) uses LocalSizeId.
        chained.vulkan13.maintenance4 = VK_TRUE;
        chained.vulkan12.timelineSemaphore = VK_TRUE;
        // The extensions' structs only when asked for: a device without them must not see them.
        void* extensions = const_cast<void*>(info.next);
        chain_if(wants_mesh_shader(info), chained.mesh_shader, extensions);
        chain_if(wants_ray_query(info), chained.ray_query, extensions);
        chain_if(wants_ray_tracing_pipeline(info), chained.ray_tracing_pipeline, extensions);
        chain_if(wants_acceleration_structure(info), chained.acceleration_structure, extensions);
        chained.vulkan13.pNext = extensions;
        chained.vulkan12.pNext = &chained.vulkan13;
        chained.vulkan11.pNext = &chained.vulkan12;
        features.pNext = &chained.vulkan11;
        features.features = info.enabled_features;
    }
    FeatureChain(const FeatureChain&) = delete;
    FeatureChain& operator=(const FeatureChain&) = delete;
    // What the chain enables, unchained.
    DeviceFeatures enabled() const {
        DeviceFeatures d = chained;
        d.core = features.features;
        d.vulkan11.pNext = d.vulkan12.pNext = d.vulkan13.pNext = nullptr;
        d.mesh_shader.pNext = d.acceleration_structure.pNext = d.ray_query.pNext = d.ray_tracing_pipeline.pNext =
            nullptr;
        return d;
    }

    DeviceFeatures chained;
    VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
};

void make_device(const PhysicalDevice& physical, VkDevice raw, Ownership ownership, Span<const QueueRequest> queues,
                 Span<const char* const> extensions, const DeviceFeatures& features,
                 detail::Ref<detail::DeviceState>& state) {
    state = detail::Ref<detail::DeviceState>(new detail::DeviceState);
    auto& s = *state;
    s.device = raw;
    s.ownership = ownership;
    s.physical_device = physical;
    s.fn = DeviceFunctions::load(physical.fn().vkGetDeviceProcAddr, raw);
    drop_unless_debug_utils(physical, s.fn);
    for (const char* e : extensions) s.enabled_extensions.push_back(e);
    s.enabled_features = features;
    init_queues(s, queues);
    assign_roles(s);
}

}  // namespace

Device Device::create(const PhysicalDevice& physical) { return create(physical, DeviceCreateInfo{}); }

Device Device::create(const PhysicalDevice& physical, const DeviceCreateInfo& info) {
    const detail::Caller caller{"vkrc::Device::create"};
    caller.require_handle(physical, "the PhysicalDevice");
    std::vector<QueueRequest> requests(info.queue_requests.begin(), info.queue_requests.end());
    if (requests.empty()) add_role_requests(caller, physical, info, requests);
    const auto queue_infos = queue_create_infos(caller, physical, requests);
    const auto extensions = device_extensions(physical, info);
    const FeatureChain features(info);

    VkDeviceCreateInfo ci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &features.features};
    ci.queueCreateInfoCount = static_cast<std::uint32_t>(queue_infos.size());
    ci.pQueueCreateInfos = queue_infos.data();
    ci.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
    ci.ppEnabledExtensionNames = extensions.data();

    VkDevice raw = VK_NULL_HANDLE;
    check(physical.fn().vkCreateDevice(physical.vk(), &ci, nullptr, &raw), "vkCreateDevice");
    detail::Ref<detail::DeviceState> state;
    try {
        make_device(physical, raw, Ownership::owned, requests, extensions, features.enabled(), state);
    } catch (...) {
        if (!state) destroy_raw_device(physical, raw);
        throw;  // otherwise the state's destructor destroyed the device
    }
    return Device(std::move(state));
}

Device Device::adopt(const PhysicalDevice& physical, VkDevice raw, Ownership ownership, Span<const QueueRequest> queues,
                     Span<const char* const> enabled_extensions) {
    const detail::Caller caller{"vkrc::Device::adopt"};
    caller.require_handle(physical, "the PhysicalDevice");
    caller.require_not_null(raw, "VkDevice");
    detail::Ref<detail::DeviceState> state;
    try {
        make_device(physical, raw, ownership, queues, enabled_extensions, physical.features(), state);
    } catch (...) {
        if (!state && ownership == Ownership::owned) destroy_raw_device(physical, raw);
        throw;
    }
    return Device(std::move(state));
}

bool Device::extension_enabled(const char* name) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::Device::extension_enabled");
    return detail::contains(state_->enabled_extensions, name);
}

Queue Device::queue(std::uint32_t family_index, std::uint32_t index) const {
    const detail::Caller caller{"vkrc::Device::queue"};
    VKRC_REQUIRE_STATE(caller.name());
    for (auto& q : state_->queues) {
        if (q.family_index == family_index && q.index == index) return Queue(*this, &q);
    }
    caller.refuse("queue ", index, " of family ", family_index, " was not requested when the device was created");
}

Queue Device::default_queue() const {
    const detail::Caller caller{"vkrc::Device::default_queue"};
    VKRC_REQUIRE_STATE(caller.name());
    caller.require(!state_->queues.empty(), "the device has no queues");
    return Queue(*this, &state_->queues.front());
}

QueueAssignment Device::queue_for(QueueRole role) const {
    const detail::Caller caller{"vkrc::Device::queue_for"};
    VKRC_REQUIRE_STATE(caller.name());
    caller.require(!state_->queues.empty(), "the device has no queues");
    const std::size_t index = state_->role_queues[static_cast<int>(role)];
    const std::size_t graphics = state_->role_queues[static_cast<int>(QueueRole::graphics)];
    QueueAssignment a;
    a.queue = Queue(*this, &state_->queues[index]);
    a.dedicated_family =
        static_cast<int>(state_->queues[index].family_index) == find_dedicated_queue_family(physical_device(), role);
    a.shares_graphics_queue = role != QueueRole::graphics && index == graphics;
    return a;
}

void Device::wait_idle() const {
    VKRC_REQUIRE_STATE("vkrc::Device::wait_idle");
    // Everything submitted before the wait is complete after it.
    std::vector<std::uint64_t> submitted;
    for (auto& q : state_->queues) submitted.push_back(q.timeline.last_submitted());
    VkResult r = fn().vkDeviceWaitIdle(vk());
    if (r == VK_SUCCESS) {
        for (std::size_t i = 0; i < submitted.size(); ++i) state_->queues[i].timeline.note_completed(submitted[i]);
    }
    state_->finish_call(r, "vkDeviceWaitIdle");
}

VkResult detail::DeviceState::finish_failed_call(VkResult r, const char* call) {
    note_result(r);
    collect();
    return check(r, call);
}

void detail::DeviceState::fail_submit(VkResult r, FencedSubmission* fenced) {
    if (fenced) fenced->queue = nullptr;
    note_result(r);
    collect();
    throw_vk_error(r, "vkQueueSubmit2");
}

void Device::collect_garbage() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::Device::collect_garbage");
    state_->collect();
}
std::size_t Device::deferred_count() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::Device::deferred_count").deferred_count();
}
bool Device::lost() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::Device::lost").lost.load(std::memory_order_relaxed);
}

VkResult detail::DeviceState::submit_signalling(QueueState& q, Span<const VkSubmitInfo2> submits, VkFence fence,
                                                std::uint64_t number) noexcept {
    q.timeline.take_signal_request();
    VkSemaphoreSubmitInfo timeline{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
    timeline.semaphore = q.semaphore;
    timeline.value = number;
    timeline.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    constexpr std::uint32_t inline_signals = 8;
    VkSemaphoreSubmitInfo signals[inline_signals + 1];
    VkSubmitInfo2 tail{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    std::size_t head = submits.size();
    if (!submits.empty() && submits.back().signalSemaphoreInfoCount <= inline_signals) {
        head = submits.size() - 1;
        tail = submits.back();
        if (tail.signalSemaphoreInfoCount) {
            std::memcpy(signals, tail.pSignalSemaphoreInfos,
                        tail.signalSemaphoreInfoCount * sizeof(VkSemaphoreSubmitInfo));
        }
        signals[tail.signalSemaphoreInfoCount] = timeline;
        tail.signalSemaphoreInfoCount += 1;
        tail.pSignalSemaphoreInfos = signals;
    } else {
        tail.signalSemaphoreInfoCount = 1;
        tail.pSignalSemaphoreInfos = &timeline;
    }
    VkResult r = VK_SUCCESS;
    if (head > 0) r = fn.vkQueueSubmit2(q.queue, static_cast<std::uint32_t>(head), submits.data(), VK_NULL_HANDLE);
    const bool head_went_in = head > 0 && r == VK_SUCCESS;
    if (r == VK_SUCCESS) r = fn.vkQueueSubmit2(q.queue, 1, &tail, fence);
    if (r == VK_SUCCESS) {
        q.timeline.note_signalled(number);
    } else {
        if (head_went_in) q.timeline.note_submitted(number);
        q.timeline.request_signal();
    }
    return r;
}

std::uint64_t Queue::submit(Span<const VkSubmitInfo2> submits, VkFence fence) const {
    return device_.state()->submit(*queue_, submits, fence);
}

std::uint64_t detail::submit_signalled(const Queue& queue, Span<const VkSubmitInfo2> submits) {
    auto& q = *queue.state();
    auto& d = *queue.device().state();
    VkResult r;
    std::uint64_t number;
    {
        LockGuard lock(q.mutex);
        number = q.timeline.next_number();
        r = d.submit_signalling(q, submits, VK_NULL_HANDLE, number);
    }
    d.finish_call(r, "vkQueueSubmit2");
    return number;
}

std::uint64_t Queue::completion_value() const {
    std::uint64_t value = 0;
    check(device_.state()->signal_submitted_work(*queue_, value), "vkQueueSubmit2");
    return value;
}

void Queue::wait_idle() const {
    auto& d = *device_.state();
    VkResult r;
    std::uint64_t submitted;
    {
        LockGuard lock(queue_->mutex);
        submitted = queue_->timeline.last_submitted();
        r = d.fn.vkQueueWaitIdle(queue_->queue);
    }
    if (r == VK_SUCCESS) queue_->timeline.note_completed(submitted);
    d.finish_call(r, "vkQueueWaitIdle");
}

VKRC_END_NAMESPACE
