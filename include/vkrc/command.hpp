// Command pools, command buffers and recording (submission: vkrc/submit.hpp).
//
// Recording methods are inline: each is one call through the device function
// table with the raw handles read out of the wrappers. No allocation, no
// atomics, no locks. Anything not wrapped stays callable as
//     cmd.fn().vkCmdSetLineWidth(cmd.vk(), 2.0f);
#pragma once

#include "vkrc/pipeline.hpp"
#include "vkrc/sync.hpp"

#include <span>

VKRC_BEGIN_NAMESPACE

namespace detail {
class CommandPoolState;
class CommandBufferState;
}  // namespace detail

// Mirrors VkCommandPoolCreateInfo.
struct CommandPoolCreateInfo {
    VkCommandPoolCreateFlags flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    std::uint32_t queue_family_index = 0;
};

class CommandBuffer;

// A command pool, externally synchronised as Vulkan requires: record into the
// command buffers of one pool from one thread at a time (use a pool per
// thread). Under the multi-thread policy the pool's lock is taken by
// allocate, reset, begin and end (never per recorded command), so that the
// frees vkrc does on its own when a command buffer is dropped (on any thread)
// never race with them.
class CommandPool : public Handle<detail::CommandPoolState> {
public:
    CommandPool() noexcept = default;
    static CommandPool create(const Device& device, const CommandPoolCreateInfo& info);

    VkCommandPool vk() const VKRC_UNCHECKED_NOEXCEPT;
    const Device& device() const VKRC_UNCHECKED_NOEXCEPT;
    std::uint32_t queue_family_index() const VKRC_UNCHECKED_NOEXCEPT;

    CommandBuffer allocate(VkCommandBufferLevel level = VK_COMMAND_BUFFER_LEVEL_PRIMARY) const;
    // vkResetCommandPool: every command buffer of the pool returns to the
    // initial state. The caller ensures none is pending on the GPU.
    void reset_commands(VkCommandPoolResetFlags flags = 0) const;
    // Command buffers dropped while the GPU may use them, not yet freed.
    std::size_t pending_free_count() const;

private:
    using Handle::Handle;
};

// What a secondary command buffer inherits (VkCommandBufferInheritanceInfo,
// with VkCommandBufferInheritanceRenderingInfo for dynamic rendering). Leave
// render_pass empty and color_formats empty for secondaries used outside
// rendering; set either for RENDER_PASS_CONTINUE secondaries.
struct CommandBufferInheritance {
    RenderPass render_pass{};
    std::uint32_t subpass = 0;
    Framebuffer framebuffer{};
    std::span<const VkFormat> color_formats{};
    VkFormat depth_format = VK_FORMAT_UNDEFINED;
    VkFormat stencil_format = VK_FORMAT_UNDEFINED;
    VkSampleCountFlagBits rasterization_samples = VK_SAMPLE_COUNT_1_BIT;
};

// One attachment of dynamic rendering (VkRenderingAttachmentInfo, no resolve).
// image_view: view.vk() of an ImageView that lives until the work is submitted.
struct RenderingAttachment {
    VkImageView image_view = VK_NULL_HANDLE;
    VkImageLayout image_layout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    VkAttachmentLoadOp load_op = VK_ATTACHMENT_LOAD_OP_CLEAR;
    VkAttachmentStoreOp store_op = VK_ATTACHMENT_STORE_OP_STORE;
    VkClearValue clear_value{};
};

// VkRenderingInfo. At most max_color_attachments colour attachments.
struct RenderingInfo {
    static constexpr std::uint32_t max_color_attachments = 8;
    VkRect2D render_area{};
    std::span<const RenderingAttachment> color_attachments{};
    const RenderingAttachment* depth_attachment = nullptr;
    const RenderingAttachment* stencil_attachment = nullptr;
    VkRenderingFlags flags = 0;
    std::uint32_t layer_count = 1;
};

// A command buffer; keeps its pool alive and returns to it when dropped (once
// the GPU has finished the work submitted before the drop).
class CommandBuffer : public Handle<detail::CommandBufferState> {
public:
    CommandBuffer() noexcept = default;

    VkCommandBuffer vk() const VKRC_UNCHECKED_NOEXCEPT;
    const DeviceFunctions& fn() const VKRC_UNCHECKED_NOEXCEPT;
    const CommandPool& pool() const VKRC_UNCHECKED_NOEXCEPT;
    VkCommandBufferLevel level() const VKRC_UNCHECKED_NOEXCEPT;

    // vkBeginCommandBuffer for a primary. flags: ONE_TIME_SUBMIT (default) or
    // SIMULTANEOUS_USE, or 0 to resubmit without overlap.
    void begin(VkCommandBufferUsageFlags flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT) const;
    // vkBeginCommandBuffer for a secondary; RENDER_PASS_CONTINUE is added when
    // inheritance names a render pass or colour formats.
    void begin_secondary(const CommandBufferInheritance& inheritance = {},
                         VkCommandBufferUsageFlags flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT) const;
    void end() const;
    // vkResetCommandBuffer (the pool needs RESET_COMMAND_BUFFER_BIT). Not
    // reset(), which, as on every handle, drops this reference.
    void reset_commands(VkCommandBufferResetFlags flags = 0) const;

    // Render passes and dynamic rendering
    void begin_render_pass(const RenderPass& render_pass, const Framebuffer& framebuffer, VkRect2D render_area,
                           std::span<const VkClearValue> clear_values,
                           VkSubpassContents contents = VK_SUBPASS_CONTENTS_INLINE) const VKRC_UNCHECKED_NOEXCEPT;
    void next_subpass(VkSubpassContents contents = VK_SUBPASS_CONTENTS_INLINE) const VKRC_UNCHECKED_NOEXCEPT;
    void end_render_pass() const VKRC_UNCHECKED_NOEXCEPT;
    // With VKRC_RUNTIME_CHECKS, throws UsageError for more than
    // RenderingInfo::max_color_attachments colour attachments.
    void begin_rendering(const RenderingInfo& info) const;
    void end_rendering() const VKRC_UNCHECKED_NOEXCEPT;

    // State
    void bind_pipeline(const Pipeline& pipeline) const VKRC_UNCHECKED_NOEXCEPT;
    void bind_vertex_buffer(std::uint32_t binding, const Buffer& buffer,
                            VkDeviceSize offset = 0) const VKRC_UNCHECKED_NOEXCEPT {
        bind_vertex_buffer(binding, buffer.vk(), offset);
    }
    void bind_vertex_buffer(std::uint32_t binding, VkBuffer buffer,
                            VkDeviceSize offset = 0) const VKRC_UNCHECKED_NOEXCEPT;
    void bind_vertex_buffers(std::uint32_t first_binding, std::span<const VkBuffer> buffers,
                             std::span<const VkDeviceSize> offsets) const VKRC_UNCHECKED_NOEXCEPT;
    void bind_index_buffer(const Buffer& buffer, VkDeviceSize offset = 0,
                           VkIndexType type = VK_INDEX_TYPE_UINT32) const VKRC_UNCHECKED_NOEXCEPT {
        bind_index_buffer(buffer.vk(), offset, type);
    }
    void bind_index_buffer(VkBuffer buffer, VkDeviceSize offset = 0,
                           VkIndexType type = VK_INDEX_TYPE_UINT32) const VKRC_UNCHECKED_NOEXCEPT;
    // Binds one set at index set_index of the pipeline's layout.
    void bind_descriptor_set(const Pipeline& pipeline, std::uint32_t set_index, const DescriptorSet& set,
                             std::span<const std::uint32_t> dynamic_offsets = {}) const VKRC_UNCHECKED_NOEXCEPT;
    void bind_descriptor_sets(const Pipeline& pipeline, std::uint32_t first_set, std::span<const VkDescriptorSet> sets,
                              std::span<const std::uint32_t> dynamic_offsets = {}) const VKRC_UNCHECKED_NOEXCEPT;
    void push_constants(const PipelineLayout& layout, VkShaderStageFlags stages, std::uint32_t offset,
                        std::uint32_t size, const void* data) const VKRC_UNCHECKED_NOEXCEPT;
    template <class T>
    void push_constants(const PipelineLayout& layout, VkShaderStageFlags stages, const T& value,
                        std::uint32_t offset = 0) const VKRC_UNCHECKED_NOEXCEPT {
        push_constants(layout, stages, offset, sizeof(T), &value);
    }
    void set_viewport(const VkViewport& viewport) const VKRC_UNCHECKED_NOEXCEPT;
    void set_scissor(const VkRect2D& scissor) const VKRC_UNCHECKED_NOEXCEPT;
    // Viewport (depth 0..1) and scissor covering extent.
    void set_viewport_and_scissor(VkExtent2D extent) const VKRC_UNCHECKED_NOEXCEPT;

    // Work
    void draw(std::uint32_t vertex_count, std::uint32_t instance_count = 1, std::uint32_t first_vertex = 0,
              std::uint32_t first_instance = 0) const VKRC_UNCHECKED_NOEXCEPT;
    void draw_indexed(std::uint32_t index_count, std::uint32_t instance_count = 1, std::uint32_t first_index = 0,
                      std::int32_t vertex_offset = 0, std::uint32_t first_instance = 0) const VKRC_UNCHECKED_NOEXCEPT;
    void dispatch(std::uint32_t x, std::uint32_t y = 1, std::uint32_t z = 1) const VKRC_UNCHECKED_NOEXCEPT;
    // Typed overloads read the raw handles; raw ones are the escape hatch.
    void copy_buffer(const Buffer& src, const Buffer& dst,
                     std::span<const VkBufferCopy> regions) const VKRC_UNCHECKED_NOEXCEPT {
        copy_buffer(src.vk(), dst.vk(), regions);
    }
    void copy_buffer_to_image(const Buffer& src, const Image& dst, VkImageLayout dst_layout,
                              std::span<const VkBufferImageCopy> regions) const VKRC_UNCHECKED_NOEXCEPT {
        copy_buffer_to_image(src.vk(), dst.vk(), dst_layout, regions);
    }
    void copy_image_to_buffer(const Image& src, VkImageLayout src_layout, const Buffer& dst,
                              std::span<const VkBufferImageCopy> regions) const VKRC_UNCHECKED_NOEXCEPT {
        copy_image_to_buffer(src.vk(), src_layout, dst.vk(), regions);
    }
    void fill_buffer(const Buffer& dst, VkDeviceSize offset, VkDeviceSize size,
                     std::uint32_t data) const VKRC_UNCHECKED_NOEXCEPT {
        fill_buffer(dst.vk(), offset, size, data);
    }
    void copy_buffer(VkBuffer src, VkBuffer dst, std::span<const VkBufferCopy> regions) const VKRC_UNCHECKED_NOEXCEPT;
    void copy_buffer_to_image(VkBuffer src, VkImage dst, VkImageLayout dst_layout,
                              std::span<const VkBufferImageCopy> regions) const VKRC_UNCHECKED_NOEXCEPT;
    void copy_image_to_buffer(VkImage src, VkImageLayout src_layout, VkBuffer dst,
                              std::span<const VkBufferImageCopy> regions) const VKRC_UNCHECKED_NOEXCEPT;
    void copy_image(VkImage src, VkImageLayout src_layout, VkImage dst, VkImageLayout dst_layout,
                    std::span<const VkImageCopy> regions) const VKRC_UNCHECKED_NOEXCEPT;
    void fill_buffer(VkBuffer dst, VkDeviceSize offset, VkDeviceSize size,
                     std::uint32_t data) const VKRC_UNCHECKED_NOEXCEPT;

    // Synchronisation (synchronization2)
    void pipeline_barrier(const VkDependencyInfo& dependency) const VKRC_UNCHECKED_NOEXCEPT;
    void pipeline_barrier(std::span<const VkMemoryBarrier2> memory, std::span<const VkBufferMemoryBarrier2> buffers,
                          std::span<const VkImageMemoryBarrier2> images,
                          VkDependencyFlags flags = 0) const VKRC_UNCHECKED_NOEXCEPT;
    void set_event(const Event& event, const VkDependencyInfo& dependency) const VKRC_UNCHECKED_NOEXCEPT;
    void reset_event(const Event& event, VkPipelineStageFlags2 stage_mask) const VKRC_UNCHECKED_NOEXCEPT;

    // Secondaries: any number, passed to Vulkan in chunks from the stack.
    void execute_commands(std::span<const CommandBuffer> secondaries) const VKRC_UNCHECKED_NOEXCEPT;

    // Queries
    void reset_query_pool(const QueryPool& pool, std::uint32_t first_query,
                          std::uint32_t query_count) const VKRC_UNCHECKED_NOEXCEPT;
    void write_timestamp(VkPipelineStageFlags2 stage, const QueryPool& pool,
                         std::uint32_t query) const VKRC_UNCHECKED_NOEXCEPT;

private:
    friend class CommandPool;
    explicit CommandBuffer(detail::Ref<detail::CommandBufferState> state) noexcept;
    // The device's function table, also held by the state, copied into the
    // handle: a recording call then loads its function pointer through one
    // pointer fewer (as vk::raii's dispatcher member does), 1 to 2 % of the
    // command stage with 25 draws on an NVIDIA H200.
    const DeviceFunctions* fn_ = nullptr;
};

// An image barrier over every mip level and layer of one aspect.
VkImageMemoryBarrier2 image_barrier(VkImage image, VkImageLayout old_layout, VkImageLayout new_layout,
                                    VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                                    VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access,
                                    VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT) noexcept;
// A global memory barrier.
VkMemoryBarrier2 memory_barrier(VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                                VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access) noexcept;

namespace detail {

// After a submit that carried them: closes the ONE_TIME_SUBMIT primaries
// (OpenCommandBuffers), whose held drops then wait for that submission.
void close_submitted(std::span<const CommandBuffer> command_buffers) noexcept;

class CommandPoolState final : public RefCounted {
public:
    ~CommandPoolState() override;
    // Under mutex: frees the dropped command buffers the GPU is done with.
    void free_completed();

    Device device;
    VkCommandPool pool = VK_NULL_HANDLE;
    std::uint32_t queue_family_index = 0;
    mutable Mutex mutex;
    PoolFreeList<VkCommandBuffer> pending;  // under mutex
    List<VkCommandBuffer> scratch;          // under mutex
};

class CommandBufferState final : public RefCounted {
public:
    ~CommandBufferState() override;
    // First, so that recording reads them from the start of the block.
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    const DeviceFunctions* fn = nullptr;
    CommandPool pool;
    VkCommandBufferLevel level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    RecordingWindow window;  // registered with the device's OpenCommandBuffers
};

}  // namespace detail

inline VkCommandPool CommandPool::vk() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandPool::vk");
    return state_->pool;
}
inline const Device& CommandPool::device() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandPool::device");
    return state_->device;
}
inline std::uint32_t CommandPool::queue_family_index() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandPool::queue_family_index");
    return state_->queue_family_index;
}

inline VkCommandBuffer CommandBuffer::vk() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::vk");
    return state_->cmd;
}
inline const DeviceFunctions& CommandBuffer::fn() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::fn");
    return *fn_;
}
inline const CommandPool& CommandBuffer::pool() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::pool");
    return state_->pool;
}
inline VkCommandBufferLevel CommandBuffer::level() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::level");
    return state_->level;
}

inline void CommandBuffer::begin_render_pass(const RenderPass& render_pass, const Framebuffer& framebuffer,
                                             VkRect2D render_area, std::span<const VkClearValue> clear_values,
                                             VkSubpassContents contents) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::begin_render_pass");
    VkRenderPassBeginInfo info{};
    info.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
    info.renderPass = render_pass.vk();
    info.framebuffer = framebuffer.vk();
    info.renderArea = render_area;
    info.clearValueCount = static_cast<std::uint32_t>(clear_values.size());
    info.pClearValues = clear_values.data();
    fn_->vkCmdBeginRenderPass(state_->cmd, &info, contents);
}
inline void CommandBuffer::next_subpass(VkSubpassContents contents) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::next_subpass");
    fn_->vkCmdNextSubpass(state_->cmd, contents);
}
inline void CommandBuffer::end_render_pass() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::end_render_pass");
    fn_->vkCmdEndRenderPass(state_->cmd);
}

namespace detail {
[[noreturn]] void throw_too_many_color_attachments(std::size_t count);
}

inline void CommandBuffer::begin_rendering(const RenderingInfo& info) const {
#if VKRC_RUNTIME_CHECKS
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::begin_rendering");
    if (info.color_attachments.size() > RenderingInfo::max_color_attachments) [[unlikely]] {
        detail::throw_too_many_color_attachments(info.color_attachments.size());
    }
#endif
    auto convert = [](const RenderingAttachment& a) {
        VkRenderingAttachmentInfo r{};
        r.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
        r.imageView = a.image_view;
        r.imageLayout = a.image_layout;
        r.loadOp = a.load_op;
        r.storeOp = a.store_op;
        r.clearValue = a.clear_value;
        return r;
    };
    VkRenderingAttachmentInfo colors[RenderingInfo::max_color_attachments];
    std::uint32_t count = 0;
    for (const auto& a : info.color_attachments) {
        if (count == RenderingInfo::max_color_attachments) break;
        colors[count++] = convert(a);
    }
    VkRenderingAttachmentInfo depth, stencil;
    VkRenderingInfo r{};
    r.sType = VK_STRUCTURE_TYPE_RENDERING_INFO;
    r.flags = info.flags;
    r.renderArea = info.render_area;
    r.layerCount = info.layer_count;
    r.colorAttachmentCount = count;
    r.pColorAttachments = colors;
    if (info.depth_attachment) {
        depth = convert(*info.depth_attachment);
        r.pDepthAttachment = &depth;
    }
    if (info.stencil_attachment) {
        stencil = convert(*info.stencil_attachment);
        r.pStencilAttachment = &stencil;
    }
    fn_->vkCmdBeginRendering(state_->cmd, &r);
}
inline void CommandBuffer::end_rendering() const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::end_rendering");
    fn_->vkCmdEndRendering(state_->cmd);
}

inline void CommandBuffer::bind_pipeline(const Pipeline& pipeline) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::bind_pipeline");
    fn_->vkCmdBindPipeline(state_->cmd, pipeline.bind_point(), pipeline.vk());
}
inline void CommandBuffer::bind_vertex_buffer(std::uint32_t binding, VkBuffer buffer,
                                              VkDeviceSize offset) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::bind_vertex_buffer");
    fn_->vkCmdBindVertexBuffers(state_->cmd, binding, 1, &buffer, &offset);
}
inline void CommandBuffer::bind_vertex_buffers(std::uint32_t first_binding, std::span<const VkBuffer> buffers,
                                               std::span<const VkDeviceSize> offsets) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::bind_vertex_buffers");
    fn_->vkCmdBindVertexBuffers(state_->cmd, first_binding, static_cast<std::uint32_t>(buffers.size()), buffers.data(),
                                offsets.data());
}
inline void CommandBuffer::bind_index_buffer(VkBuffer buffer, VkDeviceSize offset,
                                             VkIndexType type) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::bind_index_buffer");
    fn_->vkCmdBindIndexBuffer(state_->cmd, buffer, offset, type);
}
inline void CommandBuffer::bind_descriptor_set(
    const Pipeline& pipeline, std::uint32_t set_index, const DescriptorSet& set,
    std::span<const std::uint32_t> dynamic_offsets) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::bind_descriptor_set");
    VkDescriptorSet raw = set.vk();
    fn_->vkCmdBindDescriptorSets(state_->cmd, pipeline.bind_point(), pipeline.layout().vk(), set_index, 1, &raw,
                                 static_cast<std::uint32_t>(dynamic_offsets.size()), dynamic_offsets.data());
}
inline void CommandBuffer::bind_descriptor_sets(
    const Pipeline& pipeline, std::uint32_t first_set, std::span<const VkDescriptorSet> sets,
    std::span<const std::uint32_t> dynamic_offsets) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::bind_descriptor_sets");
    fn_->vkCmdBindDescriptorSets(state_->cmd, pipeline.bind_point(), pipeline.layout().vk(), first_set,
                                 static_cast<std::uint32_t>(sets.size()), sets.data(),
                                 static_cast<std::uint32_t>(dynamic_offsets.size()), dynamic_offsets.data());
}
inline void CommandBuffer::push_constants(const PipelineLayout& layout, VkShaderStageFlags stages, std::uint32_t offset,
                                          std::uint32_t size, const void* data) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::push_constants");
    fn_->vkCmdPushConstants(state_->cmd, layout.vk(), stages, offset, size, data);
}
inline void CommandBuffer::set_viewport(const VkViewport& viewport) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::set_viewport");
    fn_->vkCmdSetViewport(state_->cmd, 0, 1, &viewport);
}
inline void CommandBuffer::set_scissor(const VkRect2D& scissor) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::set_scissor");
    fn_->vkCmdSetScissor(state_->cmd, 0, 1, &scissor);
}
inline void CommandBuffer::set_viewport_and_scissor(VkExtent2D extent) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::set_viewport_and_scissor");
    set_viewport({0.0f, 0.0f, static_cast<float>(extent.width), static_cast<float>(extent.height), 0.0f, 1.0f});
    set_scissor({{0, 0}, extent});
}

inline void CommandBuffer::draw(std::uint32_t vertex_count, std::uint32_t instance_count, std::uint32_t first_vertex,
                                std::uint32_t first_instance) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::draw");
    fn_->vkCmdDraw(state_->cmd, vertex_count, instance_count, first_vertex, first_instance);
}
inline void CommandBuffer::draw_indexed(std::uint32_t index_count, std::uint32_t instance_count,
                                        std::uint32_t first_index, std::int32_t vertex_offset,
                                        std::uint32_t first_instance) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::draw_indexed");
    fn_->vkCmdDrawIndexed(state_->cmd, index_count, instance_count, first_index, vertex_offset, first_instance);
}
inline void CommandBuffer::dispatch(std::uint32_t x, std::uint32_t y, std::uint32_t z) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::dispatch");
    fn_->vkCmdDispatch(state_->cmd, x, y, z);
}
inline void CommandBuffer::copy_buffer(VkBuffer src, VkBuffer dst,
                                       std::span<const VkBufferCopy> regions) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::copy_buffer");
    fn_->vkCmdCopyBuffer(state_->cmd, src, dst, static_cast<std::uint32_t>(regions.size()), regions.data());
}
inline void CommandBuffer::copy_buffer_to_image(VkBuffer src, VkImage dst, VkImageLayout dst_layout,
                                                std::span<const VkBufferImageCopy> regions) const
    VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::copy_buffer_to_image");
    fn_->vkCmdCopyBufferToImage(state_->cmd, src, dst, dst_layout, static_cast<std::uint32_t>(regions.size()),
                                regions.data());
}
inline void CommandBuffer::copy_image_to_buffer(VkImage src, VkImageLayout src_layout, VkBuffer dst,
                                                std::span<const VkBufferImageCopy> regions) const
    VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::copy_image_to_buffer");
    fn_->vkCmdCopyImageToBuffer(state_->cmd, src, src_layout, dst, static_cast<std::uint32_t>(regions.size()),
                                regions.data());
}
inline void CommandBuffer::copy_image(VkImage src, VkImageLayout src_layout, VkImage dst, VkImageLayout dst_layout,
                                      std::span<const VkImageCopy> regions) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::copy_image");
    fn_->vkCmdCopyImage(state_->cmd, src, src_layout, dst, dst_layout, static_cast<std::uint32_t>(regions.size()),
                        regions.data());
}
inline void CommandBuffer::fill_buffer(VkBuffer dst, VkDeviceSize offset, VkDeviceSize size,
                                       std::uint32_t data) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::fill_buffer");
    fn_->vkCmdFillBuffer(state_->cmd, dst, offset, size, data);
}

inline void CommandBuffer::pipeline_barrier(const VkDependencyInfo& dependency) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::pipeline_barrier");
    fn_->vkCmdPipelineBarrier2(state_->cmd, &dependency);
}
inline void CommandBuffer::pipeline_barrier(std::span<const VkMemoryBarrier2> memory,
                                            std::span<const VkBufferMemoryBarrier2> buffers,
                                            std::span<const VkImageMemoryBarrier2> images,
                                            VkDependencyFlags flags) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::pipeline_barrier");
    VkDependencyInfo d{};
    d.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO;
    d.dependencyFlags = flags;
    d.memoryBarrierCount = static_cast<std::uint32_t>(memory.size());
    d.pMemoryBarriers = memory.data();
    d.bufferMemoryBarrierCount = static_cast<std::uint32_t>(buffers.size());
    d.pBufferMemoryBarriers = buffers.data();
    d.imageMemoryBarrierCount = static_cast<std::uint32_t>(images.size());
    d.pImageMemoryBarriers = images.data();
    fn_->vkCmdPipelineBarrier2(state_->cmd, &d);
}
inline void CommandBuffer::set_event(const Event& event,
                                     const VkDependencyInfo& dependency) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::set_event");
    fn_->vkCmdSetEvent2(state_->cmd, event.vk(), &dependency);
}
inline void CommandBuffer::reset_event(const Event& event,
                                       VkPipelineStageFlags2 stage_mask) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::reset_event");
    fn_->vkCmdResetEvent2(state_->cmd, event.vk(), stage_mask);
}

inline void CommandBuffer::execute_commands(std::span<const CommandBuffer> secondaries) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::execute_commands");
    constexpr std::size_t chunk = 32;
    VkCommandBuffer raw[chunk];
    for (std::size_t i = 0; i < secondaries.size(); i += chunk) {
        std::uint32_t n = 0;
        for (std::size_t j = i; j < secondaries.size() && n < chunk; ++j) raw[n++] = secondaries[j].vk();
        fn_->vkCmdExecuteCommands(state_->cmd, n, raw);
    }
}

inline void CommandBuffer::reset_query_pool(const QueryPool& pool, std::uint32_t first_query,
                                            std::uint32_t query_count) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::reset_query_pool");
    fn_->vkCmdResetQueryPool(state_->cmd, pool.vk(), first_query, query_count);
}
inline void CommandBuffer::write_timestamp(VkPipelineStageFlags2 stage, const QueryPool& pool,
                                           std::uint32_t query) const VKRC_UNCHECKED_NOEXCEPT {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::write_timestamp");
    fn_->vkCmdWriteTimestamp2(state_->cmd, stage, pool.vk(), query);
}

VKRC_END_NAMESPACE
