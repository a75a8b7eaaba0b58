// Command pools: where command buffers come from and return to (recording:
// vkrc/command.hpp).
#pragma once

#include "vkrc/device.hpp"

#include "vkrc/detail/list.hpp"
#include "vkrc/detail/pool_free_list.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
class CommandPoolState;
}  // namespace detail

// Mirrors VkCommandPoolCreateInfo.
struct CommandPoolCreateInfo {
    // Optional (default: command buffers reset one by one).
    VkCommandPoolCreateFlags flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    // The family the pool's command buffers are submitted to (default 0; usually queue.family_index()).
    std::uint32_t queue_family_index = 0;
    // Optional pNext chain; read during create only.
    const void* next = nullptr;
};

class CommandBuffer;

// A command pool, externally synchronised as Vulkan requires: record into the
// command buffers of one pool from one thread at a time (use a pool per
// thread). A command buffer dropped on any thread goes onto the pool's list
// of pending frees under the pool's lock; allocate, reset and begin free the
// completed ones (on the pool's thread, under that lock), and take the lock
// only when the list is not empty (never per recorded command).
class CommandPool : public DeviceChild<detail::CommandPoolState, VkCommandPool> {
public:
    static CommandPool create(const Device& device, const CommandPoolCreateInfo& info);
    // Wraps a pool made elsewhere from device for queue_family_index. With
    // Ownership::owned vkrc destroys it once the GPU is done. Borrowed, its
    // maker destroys it, after the GPU is done with every command buffer vkrc
    // allocated from it; those dropped last stay allocated until then.
    static CommandPool adopt(const Device& device, VkCommandPool pool, std::uint32_t queue_family_index,
                             Ownership ownership);

    std::uint32_t queue_family_index() const VKRC_UNCHECKED_NOEXCEPT;

    CommandBuffer allocate(VkCommandBufferLevel level = VK_COMMAND_BUFFER_LEVEL_PRIMARY) const;
    // vkResetCommandPool: every command buffer of the pool returns to the
    // initial state. The caller ensures none is pending on the GPU.
    void reset_commands(VkCommandPoolResetFlags flags = 0) const;
    // Command buffers dropped while the GPU may use them, not yet freed.
    std::size_t pending_free_count() const;

private:
    using DeviceChild::DeviceChild;
};

namespace detail {

class CommandPoolState final : public DeviceChildState<VkCommandPool> {
public:
    static constexpr const char* type_name = "vkrc::CommandPool";
    ~CommandPoolState() override;
    // On the pool's thread (allocate, reset), not under mutex: frees the
    // dropped command buffers the GPU is done with. Not at begin: every
    // dropped buffer was allocated, so the next allocate or reset bounds
    // what waits. Inline: a frame loop's reset finds nothing, one load.
    void free_completed() {
        if (has_pending.load(__ATOMIC_RELAXED)) [[unlikely]]
            free_pending();
    }
    // Takes mutex and frees what is ready.
    void free_pending();
    // Under mutex: frees what is ready.
    void free_ready();
    // Under mutex: a dropped command buffer joins pending.
    void push_pending(VkCommandBuffer command_buffer, std::uint64_t serial) noexcept;

    std::uint32_t queue_family_index = 0;
    mutable Mutex mutex;
    PoolFreeList<VkCommandBuffer> pending;  // under mutex
    List<VkCommandBuffer> scratch;          // under mutex
    // Whether pending is not empty: written under mutex, read without it by
    // free_completed (a drop it misses is freed at the next one).
    detail::PolicyAtomic<bool> has_pending{false};
};

}  // namespace detail

inline std::uint32_t CommandPool::queue_family_index() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::CommandPool::queue_family_index").queue_family_index;
}

VKRC_END_NAMESPACE
