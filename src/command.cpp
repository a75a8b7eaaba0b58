#include "vkrc/command.hpp"

#include "object_state.hpp"

#include <cstring>
#include <string>

VKRC_BEGIN_NAMESPACE

namespace detail {

void throw_too_many_color_attachments(std::size_t count) {
    Caller("vkrc::CommandBuffer::begin_rendering")
        .refuse(count, " colour attachments; at most ", RenderingInfo::max_color_attachments);
}

CommandPoolState::~CommandPoolState() {
    // Destroying the pool frees its command buffers, the pending ones included;
    // it is deferred past the work submitted so far like any other object.
    destroy_owned<&DeviceFunctions::vkDestroyCommandPool>(*this, device);
}

void CommandPoolState::free_pending() {
    LockGuard lock(mutex);
    free_ready();
}

void CommandPoolState::free_ready() {
    scratch.clear();
    pending.take_ready(*device.state(), scratch);
    has_pending.store(!pending.empty(), __ATOMIC_RELAXED);
    if (!scratch.empty()) {
        device.fn().vkFreeCommandBuffers(device.vk(), handle, static_cast<std::uint32_t>(scratch.size()),
                                         scratch.data());
    }
}

void CommandPoolState::push_pending(VkCommandBuffer command_buffer, std::uint64_t serial) noexcept {
    pending.push(*device.state(), command_buffer, serial);
    has_pending.store(!pending.empty(), __ATOMIC_RELAXED);
}

CommandBufferState::~CommandBufferState() {
    if (cmd == VK_NULL_HANDLE) return;
    // Closed first: it holds nothing once gone, but a primary it was
    // executed in may still hold it.
    device().unregister_window(window);
    if (ownership == Ownership::borrowed) return;
    auto& p = *pool.state();
    LockGuard lock(p.mutex);
    p.push_pending(cmd, serial());
}

}  // namespace detail

CommandPool CommandPool::create(const Device& device, const CommandPoolCreateInfo& info) {
    detail::Caller("vkrc::CommandPool::create").require_handle(device, "the Device");
    VkCommandPoolCreateInfo ci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    ci.pNext = info.next;
    ci.flags = info.flags;
    ci.queueFamilyIndex = info.queue_family_index;
    auto s = detail::created_state<detail::CommandPoolState, &DeviceFunctions::vkCreateCommandPool>(
        device, ci, "vkCreateCommandPool");
    s->queue_family_index = info.queue_family_index;
    return CommandPool(std::move(s));
}

CommandPool CommandPool::adopt(const Device& device, VkCommandPool pool, std::uint32_t queue_family_index,
                               Ownership ownership) {
    auto s = detail::adopted_state<detail::CommandPoolState>(detail::Caller{"vkrc::CommandPool::adopt"}, device,
                                                             "the Device", pool, "VkCommandPool", ownership);
    s->queue_family_index = queue_family_index;
    return CommandPool(std::move(s));
}

namespace {
// A command buffer's state before its handle exists (allocate and adopt set cmd).
detail::Ref<detail::CommandBufferState> new_command_buffer_state(const CommandPool& pool, VkCommandBufferLevel level) {
    detail::Ref<detail::CommandBufferState> s(new detail::CommandBufferState);
    s->fn = &pool.state()->device.fn();
    s->pool = pool;
    s->level = level;
    s->window.pool = pool.state();
    s->device_state = pool.state()->device.state();
    return s;
}
}  // namespace

CommandBuffer CommandPool::allocate(VkCommandBufferLevel level) const {
    VKRC_REQUIRE_STATE("vkrc::CommandPool::allocate");
    auto& p = *state_;
    auto s = new_command_buffer_state(*this, level);
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = p.handle;
    ai.level = level;
    ai.commandBufferCount = 1;
    LockGuard lock(p.mutex);
    p.free_ready();
    check(p.device.fn().vkAllocateCommandBuffers(p.device.vk(), &ai, &s->cmd), "vkAllocateCommandBuffers");
    try {
        p.device.state()->register_window(s->window);
    } catch (...) {
        p.device.fn().vkFreeCommandBuffers(p.device.vk(), p.handle, 1, &s->cmd);
        s->cmd = VK_NULL_HANDLE;
        throw;
    }
    return CommandBuffer(std::move(s));
}

namespace {

// The first word of a dispatchable object, which the loader-driver interface
// reserves for the loader's dispatch table: the loader writes its device's
// table into every command buffer allocated from that device (vkGetDeviceProcAddr
// hands out the loader's own vkAllocateCommandBuffers for it), so two
// handles with different words belong to different devices. Without a
// loader both hold the driver's magic value, equal, and nothing is refused.
const void* dispatch_word(const void* dispatchable) noexcept {
    const void* word = nullptr;
    std::memcpy(&word, dispatchable, sizeof word);
    return word;
}

}  // namespace

CommandBuffer CommandBuffer::adopt(const CommandPool& pool, VkCommandBuffer command_buffer, VkCommandBufferLevel level,
                                   Ownership ownership) {
    const detail::Caller caller{"vkrc::CommandBuffer::adopt"};
    caller.require_handle(pool, "the CommandPool");
    caller.require_not_null(command_buffer, "VkCommandBuffer");
    caller.require(dispatch_word(command_buffer) == dispatch_word(pool.device().vk()),
                   "the VkCommandBuffer was allocated on another device than the CommandPool's (its loader dispatch "
                   "table is not the VkDevice's)");
    caller.require(level == VK_COMMAND_BUFFER_LEVEL_PRIMARY || level == VK_COMMAND_BUFFER_LEVEL_SECONDARY, "level ",
                   static_cast<int>(level), " is neither PRIMARY nor SECONDARY");
    auto s = new_command_buffer_state(pool, level);
    s->ownership = ownership;
    // Registered like an allocated one, so that drops during its recording are held.
    s->device().register_window(s->window);
    s->cmd = command_buffer;
    return CommandBuffer(std::move(s));
}

std::size_t CommandPool::pending_free_count() const {
    VKRC_REQUIRE_STATE("vkrc::CommandPool::pending_free_count");
    LockGuard lock(state_->mutex);
    return state_->pending.size();
}

CommandBuffer::CommandBuffer(detail::Ref<detail::CommandBufferState> state) noexcept
    : Handle(std::move(state)), CommandRecorder(state_->fn, state_->cmd) {}

// Out of line, unlike end(): inlined, its begin info's stack address stayed
// in a register through the caller's draw loop (GCC 12), which then kept the
// loop's bound on the stack, one load per draw.
void CommandBuffer::begin(VkCommandBufferUsageFlags flags) const {
    const detail::Caller caller{"vkrc::CommandBuffer::begin"};
    VKRC_REQUIRE_STATE(caller.name());
    auto& s = *state_;
    caller.require(s.level == VK_COMMAND_BUFFER_LEVEL_PRIMARY, "a secondary command buffer needs begin_secondary");
    const VkCommandBufferBeginInfo info{.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                                        .pNext = nullptr,
                                        .flags = flags,
                                        .pInheritanceInfo = nullptr};
    check(fn_->vkBeginCommandBuffer(cmd_, &info), "vkBeginCommandBuffer");
    s.device().open_window(s.window, (flags & VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT) != 0);
}

void CommandBuffer::begin_secondary(const CommandBufferInheritance& inheritance,
                                    VkCommandBufferUsageFlags flags) const {
    const detail::Caller caller{"vkrc::CommandBuffer::begin_secondary"};
    VKRC_REQUIRE_STATE(caller.name());
    caller.require(state_->level == VK_COMMAND_BUFFER_LEVEL_SECONDARY, "the command buffer is primary");
    VkCommandBufferInheritanceRenderingInfo rendering{VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_RENDERING_INFO};
    VkCommandBufferInheritanceInfo inherit{VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_INFO};
    if (inheritance.render_pass) {
        inherit.renderPass = inheritance.render_pass.vk();
        inherit.subpass = inheritance.subpass;
        inherit.framebuffer = inheritance.framebuffer ? inheritance.framebuffer.vk() : VK_NULL_HANDLE;
        flags |= VK_COMMAND_BUFFER_USAGE_RENDER_PASS_CONTINUE_BIT;
    } else if (!inheritance.color_formats.empty() || inheritance.depth_format != VK_FORMAT_UNDEFINED ||
               inheritance.stencil_format != VK_FORMAT_UNDEFINED) {
        rendering.colorAttachmentCount = static_cast<std::uint32_t>(inheritance.color_formats.size());
        rendering.pColorAttachmentFormats = inheritance.color_formats.data();
        rendering.depthAttachmentFormat = inheritance.depth_format;
        rendering.stencilAttachmentFormat = inheritance.stencil_format;
        rendering.rasterizationSamples = inheritance.rasterization_samples;
        inherit.pNext = &rendering;
        flags |= VK_COMMAND_BUFFER_USAGE_RENDER_PASS_CONTINUE_BIT;
    }
    VkCommandBufferBeginInfo info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    info.flags = flags;
    info.pInheritanceInfo = &inherit;
    check(fn_->vkBeginCommandBuffer(cmd_, &info), "vkBeginCommandBuffer");
    // A ONE_TIME secondary stays open until reset, re-begin or free: only a primary's submit closes it.
    state_->device().open_window(state_->window, false);
}

void CommandBuffer::reset_commands(VkCommandBufferResetFlags flags) const {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::reset_commands");
    auto& s = *state_;
    check(s.fn->vkResetCommandBuffer(s.cmd, flags), "vkResetCommandBuffer");
    s.device().close_window(s.window);
}

VKRC_END_NAMESPACE
