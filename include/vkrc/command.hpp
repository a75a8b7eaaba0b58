// Command buffers and recording (pools: vkrc/command_pool.hpp; barriers:
// vkrc/barrier.hpp; what rendering begins with: vkrc/rendering.hpp;
// submission: vkrc/submit.hpp).
//
// CommandRecorder's recording methods by topic: here render passes and
// dynamic rendering, bindings, draws and dispatches, barriers and events,
// secondaries and labels; in its bases, each in its own header that this one
// includes, the transfer commands (vkrc/command_transfer.hpp), the dynamic
// state (vkrc/command_dynamic_state.hpp), the queries
// (vkrc/command_query.hpp) and the ray tracing commands
// (vkrc/command_ray_tracing.hpp). A CommandBuffer is a CommandRecorder plus
// its lifetime (begin, end, its pool).
//
// Recording methods are inline: each is one call through the device function
// table with the raw handles read out of the wrappers. No allocation, no
// atomics, no locks. Anything not wrapped stays callable as
//     cmd.fn().vkCmdSetLineWidth(cmd.vk(), 2.0f);
#pragma once

#include "vkrc/barrier.hpp"
#include "vkrc/command_dynamic_state.hpp"
#include "vkrc/command_pool.hpp"
#include "vkrc/command_query.hpp"
#include "vkrc/command_ray_tracing.hpp"
#include "vkrc/command_transfer.hpp"
#include "vkrc/descriptor_template.hpp"
#include "vkrc/pipeline.hpp"
#include "vkrc/rendering.hpp"
#include "vkrc/sync.hpp"

#include "vkrc/detail/span.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
class CommandBufferState;

// An indirect command's stride: stride, or the command's size when stride is 0 (tightly packed).
template <class Command>
constexpr std::uint32_t indirect_stride(std::uint32_t stride) noexcept {
    return stride ? stride : std::uint32_t{sizeof(Command)};
}
}  // namespace detail

class CommandBuffer;

namespace detail {
// The raw handle of secondaries[i] (defined once CommandBuffer is complete).
VkCommandBuffer secondary_handle(const CommandBuffer* secondaries, std::size_t i) VKRC_UNCHECKED_NOEXCEPT;
}  // namespace detail

// The recording part of a CommandBuffer: its function table and raw handle
// (two pointers) and every recording method. CommandBuffer derives from it,
// so cmd.draw(...) records on a CommandBuffer; a function that records many
// commands may take a CommandRecorder by value, so the table and the handle
// stay in registers across the opaque vkCmd* calls instead of being reloaded
// from the CommandBuffer after each (as raw C with a local handle). It keeps
// nothing alive: use it only while its CommandBuffer exists. A
// default-constructed one records nothing (with VKRC_RUNTIME_CHECKS, its
// methods throw UsageError naming the call, as an empty CommandBuffer's do).
// A recording method's Raw<VkX> parameter takes the vkrc wrapper (a Buffer,
// an Image, ...) or a raw handle made by other code: one method for both. The
// methods of its bases are as much its own (see the top of this file).
class CommandRecorder : public detail::TransferCommands<CommandRecorder>,
                        public detail::DynamicStateCommands<CommandRecorder>,
                        public detail::QueryCommands<CommandRecorder>,
                        public detail::RayTracingCommands<CommandRecorder> {
public:
    CommandRecorder() noexcept = default;

    VkCommandBuffer vk() const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandRecorder::vk");
        return cmd_;
    }
    const DeviceFunctions& fn() const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandRecorder::fn");
        return *fn_;
    }

    // Render passes and dynamic rendering
    void begin_render_pass(Raw<VkRenderPass> render_pass, Raw<VkFramebuffer> framebuffer, VkRect2D render_area,
                           Span<const VkClearValue> clear_values,
                           VkSubpassContents contents = VK_SUBPASS_CONTENTS_INLINE) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::begin_render_pass");
        const VkRenderPassBeginInfo info{.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO,
                                         .pNext = nullptr,
                                         .renderPass = render_pass,
                                         .framebuffer = framebuffer,
                                         .renderArea = render_area,
                                         .clearValueCount = static_cast<std::uint32_t>(clear_values.size()),
                                         .pClearValues = clear_values.data()};
        fn_->vkCmdBeginRenderPass(cmd_, &info, contents);
    }
    void next_subpass(VkSubpassContents contents = VK_SUBPASS_CONTENTS_INLINE) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::next_subpass");
        fn_->vkCmdNextSubpass(cmd_, contents);
    }
    void end_render_pass() const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::end_render_pass");
        fn_->vkCmdEndRenderPass(cmd_);
    }
    // With VKRC_RUNTIME_CHECKS, throws UsageError for more than
    // RenderingInfo::max_color_attachments colour attachments. Always inline:
    // clang 14 called it, about 100 instructions a frame more than raw C.
    [[gnu::always_inline]] void begin_rendering(const RenderingInfo& info) const {
#if VKRC_RUNTIME_CHECKS
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::begin_rendering");
        if (info.color_attachments.size() > RenderingInfo::max_color_attachments) [[unlikely]] {
            detail::throw_too_many_color_attachments(info.color_attachments.size());
        }
#endif
        VkRenderingAttachmentInfo colors[RenderingInfo::max_color_attachments];
        const RenderingAttachment* color_attachments = info.color_attachments.data();
        const std::size_t color_count = info.color_attachments.size();
        std::uint32_t count = 0;
        for (; count < color_count && count < RenderingInfo::max_color_attachments; ++count) {
            colors[count] = detail::rendering_attachment_info(color_attachments[count]);
        }
        VkRenderingAttachmentInfo depth, stencil;
        VkRenderingInfo r{.sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
                          .pNext = info.next,
                          .flags = info.flags,
                          .renderArea = info.render_area,
                          .layerCount = info.layer_count,
                          .viewMask = info.view_mask,
                          .colorAttachmentCount = count,
                          .pColorAttachments = colors,
                          .pDepthAttachment = nullptr,
                          .pStencilAttachment = nullptr};
        if (info.depth_attachment) {
            depth = detail::rendering_attachment_info(*info.depth_attachment);
            r.pDepthAttachment = &depth;
        }
        if (info.stencil_attachment) {
            stencil = detail::rendering_attachment_info(*info.stencil_attachment);
            r.pStencilAttachment = &stencil;
        }
        fn_->vkCmdBeginRendering(cmd_, &r);
    }
    void end_rendering() const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::end_rendering");
        fn_->vkCmdEndRendering(cmd_);
    }

    // Bindings (the dynamic state: vkrc/command_dynamic_state.hpp)
    // Each binding by a wrapper is followed by its twin by raw handles or a
    // PipelineLayout, for pipelines and layouts made by other code (or
    // adopted): the same single call.
    void bind_pipeline(const Pipeline& pipeline) const VKRC_UNCHECKED_NOEXCEPT {
        bind_pipeline(pipeline.bind_point(), pipeline.vk());
    }
    void bind_pipeline(VkPipelineBindPoint bind_point, VkPipeline pipeline) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::bind_pipeline");
        fn_->vkCmdBindPipeline(cmd_, bind_point, pipeline);
    }
    void bind_vertex_buffer(std::uint32_t binding, Raw<VkBuffer> buffer,
                            VkDeviceSize offset = 0) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::bind_vertex_buffer");
        fn_->vkCmdBindVertexBuffers(cmd_, binding, 1, buffer.get(), &offset);
    }
    void bind_vertex_buffers(std::uint32_t first_binding, Span<const VkBuffer> buffers,
                             Span<const VkDeviceSize> offsets) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::bind_vertex_buffers");
        fn_->vkCmdBindVertexBuffers(cmd_, first_binding, static_cast<std::uint32_t>(buffers.size()), buffers.data(),
                                    offsets.data());
    }
    // vkCmdBindVertexBuffers2: sizes and strides empty or one per buffer
    // (strides need VERTEX_INPUT_BINDING_STRIDE dynamic).
    void bind_vertex_buffers2(std::uint32_t first_binding, Span<const VkBuffer> buffers,
                              Span<const VkDeviceSize> offsets, Span<const VkDeviceSize> sizes = {},
                              Span<const VkDeviceSize> strides = {}) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::bind_vertex_buffers2");
        fn_->vkCmdBindVertexBuffers2(cmd_, first_binding, static_cast<std::uint32_t>(buffers.size()), buffers.data(),
                                     offsets.data(), sizes.empty() ? nullptr : sizes.data(),
                                     strides.empty() ? nullptr : strides.data());
    }
    void bind_index_buffer(Raw<VkBuffer> buffer, VkDeviceSize offset = 0,
                           VkIndexType type = VK_INDEX_TYPE_UINT32) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::bind_index_buffer");
        fn_->vkCmdBindIndexBuffer(cmd_, buffer, offset, type);
    }
    // Binds one set at index set_index of the pipeline's layout.
    void bind_descriptor_set(const Pipeline& pipeline, std::uint32_t set_index, const DescriptorSet& set,
                             Span<const std::uint32_t> dynamic_offsets = {}) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::bind_descriptor_set");
        const VkDescriptorSet raw = set.vk();
        bind_descriptor_sets(pipeline.bind_point(), pipeline.layout().vk(), set_index, Span(&raw, 1), dynamic_offsets);
    }
    void bind_descriptor_sets(const Pipeline& pipeline, std::uint32_t first_set, Span<const VkDescriptorSet> sets,
                              Span<const std::uint32_t> dynamic_offsets = {}) const VKRC_UNCHECKED_NOEXCEPT {
        bind_descriptor_sets(pipeline.bind_point(), pipeline.layout().vk(), first_set, sets, dynamic_offsets);
    }
    void bind_descriptor_sets(VkPipelineBindPoint bind_point, Raw<VkPipelineLayout> layout, std::uint32_t first_set,
                              Span<const VkDescriptorSet> sets,
                              Span<const std::uint32_t> dynamic_offsets = {}) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::bind_descriptor_sets");
        fn_->vkCmdBindDescriptorSets(cmd_, bind_point, layout, first_set, static_cast<std::uint32_t>(sets.size()),
                                     sets.data(), static_cast<std::uint32_t>(dynamic_offsets.size()),
                                     dynamic_offsets.data());
    }
    // Push descriptors (VK_KHR_push_descriptor, which must be enabled on the
    // device: the function is called as loaded). Writes set `set` of layout,
    // whose set layout has PUSH_DESCRIPTOR_BIT_KHR; the writes' dstSet is ignored.
    void push_descriptor_set(VkPipelineBindPoint bind_point, Raw<VkPipelineLayout> layout, std::uint32_t set,
                             Span<const VkWriteDescriptorSet> writes) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::push_descriptor_set");
        fn_->vkCmdPushDescriptorSetKHR(cmd_, bind_point, layout, set, static_cast<std::uint32_t>(writes.size()),
                                       writes.data());
    }
    // The same through a PUSH_DESCRIPTORS_KHR template, to its pipeline layout and set.
    void push_descriptor_set_with_template(const DescriptorUpdateTemplate& update_template,
                                           const void* data) const VKRC_UNCHECKED_NOEXCEPT {
        push_descriptor_set_with_template(update_template.vk(), update_template.pipeline_layout().vk(),
                                          update_template.set(), data);
    }
    // Raw: layout and set must be those the template was created with (Vulkan's rule).
    void push_descriptor_set_with_template(VkDescriptorUpdateTemplate update_template, VkPipelineLayout layout,
                                           std::uint32_t set, const void* data) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::push_descriptor_set_with_template");
        fn_->vkCmdPushDescriptorSetWithTemplateKHR(cmd_, update_template, layout, set, data);
    }
    // value's bytes at offset; layout is a PipelineLayout or a raw VkPipelineLayout (as below).
    template <class Layout, class T>
    void push_constants(const Layout& layout, VkShaderStageFlags stages, const T& value,
                        std::uint32_t offset = 0) const VKRC_UNCHECKED_NOEXCEPT {
        push_constants(layout, stages, offset, sizeof(T), &value);
    }
    // With VKRC_RUNTIME_CHECKS, UsageError naming the layout's ranges when
    // [offset, offset + size) and stages are outside them (see
    // detail::check_push_constants); a raw or adopted layout is not checked.
    void push_constants(const PipelineLayout& layout, VkShaderStageFlags stages, std::uint32_t offset,
                        std::uint32_t size, const void* data) const VKRC_UNCHECKED_NOEXCEPT {
#if VKRC_RUNTIME_CHECKS
        detail::check_push_constants(layout, stages, offset, size);
#endif
        push_constants(layout.vk(), stages, offset, size, data);
    }
    void push_constants(VkPipelineLayout layout, VkShaderStageFlags stages, std::uint32_t offset, std::uint32_t size,
                        const void* data) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::push_constants");
        fn_->vkCmdPushConstants(cmd_, layout, stages, offset, size, data);
    }
    // Work
    void draw(std::uint32_t vertex_count, std::uint32_t instance_count = 1, std::uint32_t first_vertex = 0,
              std::uint32_t first_instance = 0) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::draw");
        fn_->vkCmdDraw(cmd_, vertex_count, instance_count, first_vertex, first_instance);
    }
    void draw_indexed(std::uint32_t index_count, std::uint32_t instance_count = 1, std::uint32_t first_index = 0,
                      std::int32_t vertex_offset = 0, std::uint32_t first_instance = 0) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::draw_indexed");
        fn_->vkCmdDrawIndexed(cmd_, index_count, instance_count, first_index, vertex_offset, first_instance);
    }
    void dispatch(std::uint32_t x, std::uint32_t y = 1, std::uint32_t z = 1) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::dispatch");
        fn_->vkCmdDispatch(cmd_, x, y, z);
    }

    // Indirect work: parameters read by the GPU from buffer (INDIRECT_BUFFER
    // usage) at execution. stride 0 means tightly packed commands.
    void draw_indirect(Raw<VkBuffer> buffer, VkDeviceSize offset, std::uint32_t draw_count,
                       std::uint32_t stride = 0) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::draw_indirect");
        fn_->vkCmdDrawIndirect(cmd_, buffer, offset, draw_count,
                               detail::indirect_stride<VkDrawIndirectCommand>(stride));
    }
    void draw_indexed_indirect(Raw<VkBuffer> buffer, VkDeviceSize offset, std::uint32_t draw_count,
                               std::uint32_t stride = 0) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::draw_indexed_indirect");
        fn_->vkCmdDrawIndexedIndirect(cmd_, buffer, offset, draw_count,
                                      detail::indirect_stride<VkDrawIndexedIndirectCommand>(stride));
    }
    void dispatch_indirect(Raw<VkBuffer> buffer, VkDeviceSize offset = 0) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::dispatch_indirect");
        fn_->vkCmdDispatchIndirect(cmd_, buffer, offset);
    }
    // The draw count comes from count_buffer (a uint32 at count_offset),
    // clamped to max_draw_count. Needs the Vulkan 1.2 drawIndirectCount feature.
    void draw_indirect_count(Raw<VkBuffer> buffer, VkDeviceSize offset, Raw<VkBuffer> count_buffer,
                             VkDeviceSize count_offset, std::uint32_t max_draw_count,
                             std::uint32_t stride = 0) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::draw_indirect_count");
        fn_->vkCmdDrawIndirectCount(cmd_, buffer, offset, count_buffer, count_offset, max_draw_count,
                                    detail::indirect_stride<VkDrawIndirectCommand>(stride));
    }
    void draw_indexed_indirect_count(Raw<VkBuffer> buffer, VkDeviceSize offset, Raw<VkBuffer> count_buffer,
                                     VkDeviceSize count_offset, std::uint32_t max_draw_count,
                                     std::uint32_t stride = 0) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::draw_indexed_indirect_count");
        fn_->vkCmdDrawIndexedIndirectCount(cmd_, buffer, offset, count_buffer, count_offset, max_draw_count,
                                           detail::indirect_stride<VkDrawIndexedIndirectCommand>(stride));
    }

    // Mesh shading (VK_EXT_mesh_shader: DeviceCreateInfo::mesh_shader_features)
    // with a pipeline that has a mesh stage: group_count_x * y * z workgroups
    // of the task shader, or of the mesh shader when there is none.
    void draw_mesh_tasks(std::uint32_t group_count_x, std::uint32_t group_count_y = 1,
                         std::uint32_t group_count_z = 1) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::draw_mesh_tasks");
        fn_->vkCmdDrawMeshTasksEXT(cmd_, group_count_x, group_count_y, group_count_z);
    }
    // The group counts from VkDrawMeshTasksIndirectCommandEXTs in buffer, as draw_indirect.
    void draw_mesh_tasks_indirect(Raw<VkBuffer> buffer, VkDeviceSize offset, std::uint32_t draw_count,
                                  std::uint32_t stride = 0) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::draw_mesh_tasks_indirect");
        fn_->vkCmdDrawMeshTasksIndirectEXT(cmd_, buffer, offset, draw_count,
                                           detail::indirect_stride<VkDrawMeshTasksIndirectCommandEXT>(stride));
    }
    // The draw count from count_buffer as draw_indirect_count (also needs drawIndirectCount).
    void draw_mesh_tasks_indirect_count(Raw<VkBuffer> buffer, VkDeviceSize offset, Raw<VkBuffer> count_buffer,
                                        VkDeviceSize count_offset, std::uint32_t max_draw_count,
                                        std::uint32_t stride = 0) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::draw_mesh_tasks_indirect_count");
        fn_->vkCmdDrawMeshTasksIndirectCountEXT(cmd_, buffer, offset, count_buffer, count_offset, max_draw_count,
                                                detail::indirect_stride<VkDrawMeshTasksIndirectCommandEXT>(stride));
    }

    // Synchronisation (synchronization2)
    void pipeline_barrier(const VkDependencyInfo& dependency) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::pipeline_barrier");
        fn_->vkCmdPipelineBarrier2(cmd_, &dependency);
    }
    // The barriers' structs: vkrc/barrier.hpp.
    void pipeline_barrier(Span<const VkMemoryBarrier2> memory, Span<const VkBufferMemoryBarrier2> buffers,
                          Span<const VkImageMemoryBarrier2> images,
                          VkDependencyFlags flags = 0) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::pipeline_barrier");
        const VkDependencyInfo d{.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO,
                                 .pNext = nullptr,
                                 .dependencyFlags = flags,
                                 .memoryBarrierCount = static_cast<std::uint32_t>(memory.size()),
                                 .pMemoryBarriers = memory.data(),
                                 .bufferMemoryBarrierCount = static_cast<std::uint32_t>(buffers.size()),
                                 .pBufferMemoryBarriers = buffers.data(),
                                 .imageMemoryBarrierCount = static_cast<std::uint32_t>(images.size()),
                                 .pImageMemoryBarriers = images.data()};
        fn_->vkCmdPipelineBarrier2(cmd_, &d);
    }
    void set_event(Raw<VkEvent> event, const VkDependencyInfo& dependency) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::set_event");
        fn_->vkCmdSetEvent2(cmd_, event, &dependency);
    }
    void reset_event(Raw<VkEvent> event, VkPipelineStageFlags2 stage_mask) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::reset_event");
        fn_->vkCmdResetEvent2(cmd_, event, stage_mask);
    }

    // Secondaries: any number, passed to Vulkan in chunks from the stack.
    void execute_commands(Span<const CommandBuffer> secondaries) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::execute_commands");
        constexpr std::size_t chunk = 32;
        VkCommandBuffer raw[chunk];
        for (std::size_t i = 0; i < secondaries.size(); i += chunk) {
            std::uint32_t n = 0;
            for (std::size_t j = i; j < secondaries.size() && n < chunk; ++j) {
                raw[n++] = detail::secondary_handle(secondaries.data(), j);
            }
            fn_->vkCmdExecuteCommands(cmd_, n, raw);
        }
    }
    // Raw secondaries (recorded by other code): passed as they are, in one call.
    void execute_commands(Span<const VkCommandBuffer> secondaries) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::execute_commands");
        fn_->vkCmdExecuteCommands(cmd_, static_cast<std::uint32_t>(secondaries.size()), secondaries.data());
    }

    // Debug-utils labels around and between commands, shown by debuggers and
    // capture tools. No-ops when the instance has not enabled
    // VK_EXT_debug_utils, so they may stay in release code. name is copied.
    void begin_label(const char* name, const LabelColor& color = {}) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::begin_label");
        if (auto f = fn_->vkCmdBeginDebugUtilsLabelEXT) {
            const VkDebugUtilsLabelEXT label = detail::debug_label(name, color);
            f(cmd_, &label);
        }
    }
    void end_label() const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::end_label");
        if (auto f = fn_->vkCmdEndDebugUtilsLabelEXT) f(cmd_);
    }
    void insert_label(const char* name, const LabelColor& color = {}) const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_RECORDER("vkrc::CommandBuffer::insert_label");
        if (auto f = fn_->vkCmdInsertDebugUtilsLabelEXT) {
            const VkDebugUtilsLabelEXT label = detail::debug_label(name, color);
            f(cmd_, &label);
        }
    }

private:
    friend class CommandBuffer;
    CommandRecorder(const DeviceFunctions* fn, VkCommandBuffer cmd) noexcept : fn_(fn), cmd_(cmd) {}
    // Copies of the state's table and handle: a recording call loads both
    // straight from here (as vk::raii's members are), one pointer chase
    // fewer each; 1 to 2 % of the command stage with 25 draws on an NVIDIA
    // H200 for the table alone.
    const DeviceFunctions* fn_ = nullptr;
    VkCommandBuffer cmd_ = VK_NULL_HANDLE;

    // The bases' way in: their methods record through the fn_ and cmd_ of
    // recording(*this, who), the recorder the base is part of, checked as
    // VKRC_REQUIRE_RECORDER checks (who names the method).
    friend class detail::TransferCommands<CommandRecorder>;
    friend class detail::DynamicStateCommands<CommandRecorder>;
    friend class detail::QueryCommands<CommandRecorder>;
    friend class detail::RayTracingCommands<CommandRecorder>;
    template <class Base>
    static const CommandRecorder& recording(const Base& base,
                                            [[maybe_unused]] const char* who) VKRC_UNCHECKED_NOEXCEPT {
        const auto& self = static_cast<const CommandRecorder&>(base);
#if VKRC_RUNTIME_CHECKS
        if (!self.cmd_) [[unlikely]]
            detail::throw_empty_handle(who);
#endif
        return self;
    }
};
// The bases are empty: a recorder is the table and the raw handle.
static_assert(sizeof(CommandRecorder) == 2 * sizeof(void*));

// A command buffer; keeps its pool alive and returns to it when dropped (once
// the GPU has finished the work submitted before the drop). Its recording
// methods are its CommandRecorder's; a moved-from or reset() one is empty,
// its recorder part included.
class CommandBuffer : public Handle<detail::CommandBufferState>, public CommandRecorder {
public:
    CommandBuffer() noexcept = default;
    // A command buffer of level allocated by other code from pool's Vulkan
    // pool, not recording (vkrc tracks recording from its begin()). Owned:
    // dropping it frees it back to the pool like an allocated one (once the
    // work submitted through vkrc is done); borrowed: vkrc never frees it, and
    // its maker frees it after every vkrc handle to it has gone. Work its
    // maker submitted outside vkrc must be complete before an owned one is dropped.
    static CommandBuffer adopt(const CommandPool& pool, VkCommandBuffer command_buffer, VkCommandBufferLevel level,
                               Ownership ownership);

    VkCommandBuffer vk() const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_STATE("vkrc::CommandBuffer::vk");
        return cmd_;
    }
    const DeviceFunctions& fn() const VKRC_UNCHECKED_NOEXCEPT {
        VKRC_REQUIRE_STATE("vkrc::CommandBuffer::fn");
        return *fn_;
    }
    const CommandPool& pool() const VKRC_UNCHECKED_NOEXCEPT;
    VkCommandBufferLevel level() const VKRC_UNCHECKED_NOEXCEPT;

    // vkBeginCommandBuffer for a primary. flags: ONE_TIME_SUBMIT (default) or
    // SIMULTANEOUS_USE, or 0 to resubmit without overlap. end() and
    // CommandPool::reset_commands are inline; begin() is not (src/command.cpp says why).
    void begin(VkCommandBufferUsageFlags flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT) const;
    // vkBeginCommandBuffer for a secondary; RENDER_PASS_CONTINUE is added when
    // inheritance names a render pass or colour formats.
    void begin_secondary(const CommandBufferInheritance& inheritance = {},
                         VkCommandBufferUsageFlags flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT) const;
    void end() const;
    // vkResetCommandBuffer (the pool needs RESET_COMMAND_BUFFER_BIT). Not
    // reset(), which, as on every handle, drops this reference.
    void reset_commands(VkCommandBufferResetFlags flags = 0) const;

    // A move empties other's recorder part with its state, so that recording
    // through a moved-from CommandBuffer fails the same checks as an empty one.
    CommandBuffer(const CommandBuffer&) noexcept = default;
    CommandBuffer& operator=(const CommandBuffer&) noexcept = default;
    CommandBuffer(CommandBuffer&& other) noexcept
        : Handle(moves::move(static_cast<Handle&>(other))), CommandRecorder(other) {
        other.clear_recorder();
    }
    CommandBuffer& operator=(CommandBuffer&& other) noexcept {
        const CommandRecorder recorder = other;
        Handle::operator=(moves::move(static_cast<Handle&>(other)));
        other.clear_recorder();
        static_cast<CommandRecorder&>(*this) = recorder;
        return *this;
    }
    // Drops this handle's reference (hides Handle::reset, which would leave the recorder).
    void reset() noexcept {
        Handle::reset();
        clear_recorder();
    }

private:
    friend class CommandPool;
    explicit CommandBuffer(detail::Ref<detail::CommandBufferState> state) noexcept;
    void clear_recorder() noexcept { static_cast<CommandRecorder&>(*this) = CommandRecorder(); }
};
// The state, then the recorder's table and raw handle.
static_assert(sizeof(CommandBuffer) == 3 * sizeof(void*));

namespace detail {

inline VkCommandBuffer secondary_handle(const CommandBuffer* secondaries, std::size_t i) VKRC_UNCHECKED_NOEXCEPT {
    return secondaries[i].vk();
}

class CommandBufferState final : public RefCounted {
public:
    ~CommandBufferState() override;
    // First, so that recording reads them from the start of the block.
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    const DeviceFunctions* fn = nullptr;
    CommandPool pool;
    VkCommandBufferLevel level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    Ownership ownership = Ownership::owned;  // borrowed (adopted): never freed by vkrc
    RecordingWindow window;                  // registered with the device's OpenCommandBuffers
    // The pool's device (kept alive through pool), whose OpenCommandBuffers
    // keeps window: one load for begin, end and submit rather than three.
    DeviceState* device_state = nullptr;
    DeviceState& device() const noexcept { return *device_state; }
};

// After a submit that carried them: closes the ONE_TIME_SUBMIT primaries
// (OpenCommandBuffers), whose held drops then wait for that submission.
// Inline: a frame's submit closes one command buffer.
inline void close_submitted(Span<const CommandBuffer> command_buffers) noexcept {
    // By index: GCC then sees a one-element span's single iteration.
    for (std::size_t i = 0; i < command_buffers.size(); ++i) {
        auto& s = *command_buffers[i].state();
        if (s.window.one_time) s.device().close_window(s.window);
    }
}

}  // namespace detail

inline void CommandBuffer::end() const {
    VKRC_REQUIRE_STATE("vkrc::CommandBuffer::end");
    // Before the driver's call: the window's end is a locked add, which
    // would wait there for the stores vkEndCommandBuffer leaves buffered.
    // Recording is over either way; a failed end leaves a command buffer
    // that cannot be submitted, and the window closes at reset or free.
    state_->device().end_window(state_->window);
    check(fn_->vkEndCommandBuffer(cmd_), "vkEndCommandBuffer");
}

inline void CommandPool::reset_commands(VkCommandPoolResetFlags flags) const {
    VKRC_REQUIRE_STATE("vkrc::CommandPool::reset_commands");
    auto& p = *state_;
    p.free_completed();
    check(p.device.fn().vkResetCommandPool(p.device.vk(), p.handle, flags), "vkResetCommandPool");
    p.device.state()->close_pool_windows(&p);
}

inline const CommandPool& CommandBuffer::pool() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::CommandBuffer::pool").pool;
}
inline VkCommandBufferLevel CommandBuffer::level() const VKRC_UNCHECKED_NOEXCEPT {
    return live("vkrc::CommandBuffer::level").level;
}

VKRC_END_NAMESPACE
