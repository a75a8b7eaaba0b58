// Logical device, queues, and deferred destruction of device children.
#pragma once

#include "vkrc/instance.hpp"

#include "vkrc/detail/list.hpp"
#include "vkrc/detail/span.hpp"

VKRC_BEGIN_NAMESPACE

class DeviceAllocator;

namespace detail {
class DeviceState;
class DeviceLink;
class QueueState;
}  // namespace detail

// Queues wanted from one family (VkDeviceQueueCreateInfo).
struct QueueRequest {
    // Must exist on the device (default 0).
    std::uint32_t queue_family_index = 0;
    // One per queue, 1 to the family's queueCount (default one queue, priority 1).
    List<float> queue_priorities = {1.0f};
    // Optional pNext chain of VkDeviceQueueCreateInfo (e.g. a global
    // priority); read during Device::create only. Ignored by Device::adopt.
    const void* next = nullptr;
};

// What a queue is for. Every device has a queue for each role: one it was
// given, or the graphics queue when it has none of its own (see
// DeviceCreateInfo::transfer_queue and Device::queue_for).
enum class QueueRole : std::uint8_t { graphics, transfer, compute };

// The family the queues of role would best come from, as vk-bootstrap looks
// for it: transfer, a family with transfer and neither graphics nor compute;
// compute, a family with compute and no graphics; graphics, the first family
// with graphics and compute. -1 when the device has no such family.
int find_dedicated_queue_family(const PhysicalDevice& physical_device, QueueRole role);

// Mirrors VkDeviceCreateInfo. vkrc always turns on timelineSemaphore,
// synchronization2, dynamicRendering and maintenance4 (it is built on them, and
// SPIR-V compiled for Vulkan 1.3 needs maintenance4); set any other
// feature in the structs below. vkrc fills their sType and pNext.
// Every member is optional and read during create() (lists and extension names
// are copied): nothing need outlive the call.
struct DeviceCreateInfo {
    // Empty: one queue from the physical device's default_queue_family() (the
    // one select() chose: it presents when a surface was asked for) if it has
    // graphics and compute, else from the first family that has both; plus
    // the transfer and compute queues asked for below.
    List<QueueRequest> queue_requests{};
    // With queue_requests empty: also a queue for transfers (streaming) and
    // one for async compute, each from its dedicated family when the device
    // has one, else another queue of the graphics family when it has room,
    // else none (the role then shares the graphics queue). Device::queue_for
    // reports what each role got. With queue_requests set, the roles are
    // given to the requested queues (see queue_for) and these are ignored.
    // Default false.
    bool transfer_queue = false;
    bool compute_queue = false;
    // Default none (vkrc adds VK_EXT_memory_budget, see below).
    List<const char*> enabled_extension_names{};
    // Default none (besides the four above).
    VkPhysicalDeviceFeatures enabled_features{};
    VkPhysicalDeviceVulkan11Features vulkan11_features{};
    VkPhysicalDeviceVulkan12Features vulkan12_features{};
    VkPhysicalDeviceVulkan13Features vulkan13_features{};
    // With any feature set, vkrc chains it and enables VK_EXT_mesh_shader
    // (mesh and task shaders: GraphicsPipelineBuilder, draw_mesh_tasks).
    VkPhysicalDeviceMeshShaderFeaturesEXT mesh_shader_features{};
    // Chained when any of their features is set, which also enables the
    // extension (and VK_KHR_deferred_host_operations, which
    // VK_KHR_acceleration_structure needs). Default none.
    VkPhysicalDeviceAccelerationStructureFeaturesKHR acceleration_structure_features{};
    VkPhysicalDeviceRayQueryFeaturesKHR ray_query_features{};
    // With any feature set, vkrc chains it and enables VK_KHR_ray_tracing_pipeline
    // with VK_KHR_acceleration_structure, which it depends on (RayTracingPipeline,
    // trace_rays: vkrc/ray_tracing.hpp). Default none.
    VkPhysicalDeviceRayTracingPipelineFeaturesKHR ray_tracing_pipeline_features{};
    // Enable VK_EXT_memory_budget when the device has it (for allocator statistics). Default true.
    bool enable_memory_budget = true;
    // Chained after vkrc's feature structs (must not repeat them). Null: none.
    const void* next = nullptr;
};

class Queue;
struct DeviceExtensionFunctions;
struct QueueAssignment;

// A logical device; keeps its PhysicalDevice (and so its Instance) alive.
class Device : public Handle<detail::DeviceState> {
public:
    static Device create(const PhysicalDevice& physical_device, const DeviceCreateInfo& info);
    // The defaults: a separate overload so that a caller's translation unit
    // does not build and destroy a default create-info (bench/header_cost).
    static Device create(const PhysicalDevice& physical_device);
    // Wraps a device made elsewhere; queues lists what it was created with.
    // Its functions are loaded with vkGetDeviceProcAddr either way.
    static Device adopt(const PhysicalDevice& physical_device, VkDevice device, Ownership ownership,
                        Span<const QueueRequest> queues, Span<const char* const> enabled_extensions = {});

    VkDevice vk() const VKRC_UNCHECKED_NOEXCEPT;
    const DeviceFunctions& fn() const VKRC_UNCHECKED_NOEXCEPT;
    // Every device-level extension command (include vkrc/extension_functions.hpp).
    const DeviceExtensionFunctions& ext_fn() const;
    const PhysicalDevice& physical_device() const VKRC_UNCHECKED_NOEXCEPT;
    const Instance& instance() const VKRC_UNCHECKED_NOEXCEPT;
    bool extension_enabled(const char* name) const VKRC_UNCHECKED_NOEXCEPT;

    // The index-th queue of a family requested at creation; throws UsageError otherwise.
    Queue queue(std::uint32_t family_index, std::uint32_t index = 0) const;
    // The first queue created (the default request's queue).
    Queue default_queue() const;
    // The queue that does role's work, and whether it is a queue of its own.
    // graphics: the first queue whose family has graphics (else the first
    // queue); transfer and compute: a queue of the role's dedicated family
    // (find_dedicated_queue_family), else another queue than graphics' that
    // can do the work (compute: also another than transfer's), else the
    // graphics queue.
    QueueAssignment queue_for(QueueRole role) const;

    // vkDeviceWaitIdle, then runs every deferred destruction.
    void wait_idle() const;
    // Runs the deferred destructions whose GPU work has completed. vkrc calls
    // this on every submit and wait; applications need not.
    void collect_garbage() const VKRC_UNCHECKED_NOEXCEPT;
    // Number of Vulkan objects and allocations waiting for the GPU, or for an
    // open command buffer that may refer to them.
    std::size_t deferred_count() const VKRC_UNCHECKED_NOEXCEPT;
    // True once any call reported VK_ERROR_DEVICE_LOST.
    bool lost() const VKRC_UNCHECKED_NOEXCEPT;

private:
    using Handle::Handle;
    friend class Queue;
    friend class detail::DeviceLink;
    // A Device over s that took no reference, for DeviceLink's view only
    // (which is never destroyed, so gives none back).
    static Device view_of(detail::DeviceState* s) noexcept { return Device(detail::Ref<detail::DeviceState>(s)); }
};

// The colour of a debug-utils label (all zero: none).
struct LabelColor {
    float r = 0.0f, g = 0.0f, b = 0.0f, a = 0.0f;
};

namespace detail {
// The label that queue and command-buffer labels pass (name is not copied:
// Vulkan reads it during the call).
inline VkDebugUtilsLabelEXT debug_label(const char* name, const LabelColor& color) noexcept {
    return {VK_STRUCTURE_TYPE_DEBUG_UTILS_LABEL_EXT, nullptr, name, {color.r, color.g, color.b, color.a}};
}
}  // namespace detail

// A queue; keeps its Device alive. Submission and presentation take the
// queue's lock under the multi-thread policy (Vulkan requires external
// synchronisation of queues); nothing else does.
class Queue {
public:
    Queue() noexcept = default;

    VkQueue vk() const noexcept;
    std::uint32_t family_index() const noexcept;
    std::uint32_t index() const noexcept;
    const Device& device() const noexcept { return device_; }
    explicit operator bool() const noexcept { return queue_ != nullptr; }

    // vkQueueSubmit2 with the batches as given. When vkrc needs to know when
    // the work submitted so far completes (an object was dropped, a pool
    // freed a command buffer, a presenter waits), the submit also signals
    // the queue's timeline semaphore, once; otherwise it is the application's
    // submit and nothing more, so a frame loop that drops nothing pays no
    // GPU-lifetime tracking at all. No heap allocation. Returns the
    // submission's number on this queue (they count up from 1).
    // Throws DeviceLostError on device loss.
    std::uint64_t submit(Span<const VkSubmitInfo2> submits, VkFence fence = VK_NULL_HANDLE) const;
    // vkQueueWaitIdle, then runs deferred destructions.
    void wait_idle() const;

    // A value of timeline_semaphore() that is reached once all work
    // submitted so far through vkrc has completed (the timeline counts in
    // submission numbers). When the last submits carried no signal, submits
    // an empty batch that signals, so the value can always be waited on.
    // Takes the queue's lock: not for the hot path.
    std::uint64_t completion_value() const;
    VkSemaphore timeline_semaphore() const noexcept;
    // The queue's lock, for applications that call vkQueue* themselves from several threads.
    Mutex& mutex() const noexcept;

    // Debug-utils labels around and between submissions (the queue's lock is
    // taken). No-ops when the instance has not enabled VK_EXT_debug_utils.
    void begin_label(const char* name, const LabelColor& color = {}) const;
    void end_label() const;
    void insert_label(const char* name, const LabelColor& color = {}) const;

    friend bool operator==(const Queue& a, const Queue& b) noexcept { return a.queue_ == b.queue_; }
    detail::QueueState* state() const noexcept { return queue_; }

private:
    friend class Device;
    Queue(Device device, detail::QueueState* queue) noexcept : device_(moves::move(device)), queue_(queue) {}
    Device device_;
    detail::QueueState* queue_ = nullptr;  // owned by the device
};

// What Device::queue_for found for a role.
struct QueueAssignment {
    Queue queue;
    // The queue's family has only the role's kind of work (find_dedicated_queue_family).
    bool dedicated_family = false;
    // The role has no queue of its own: its work goes to the graphics queue
    // (always false for graphics itself).
    bool shares_graphics_queue = false;
};

// Base of the wrappers of a DeviceChildState: the raw handle and the device.
template <class State, class VkHandle>
class DeviceChild : public VulkanObject<State, VkHandle> {
public:
    const Device& device() const VKRC_UNCHECKED_NOEXCEPT { return this->live(State::type_name, "device").device; }

protected:
    using VulkanObject<State, VkHandle>::VulkanObject;
};

VKRC_END_NAMESPACE

// The machinery behind Device and Queue, and their inline accessors.
#include "vkrc/detail/device_state.hpp"
