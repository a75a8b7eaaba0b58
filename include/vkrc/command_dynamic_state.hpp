// Dynamic state of CommandBuffer (vkrc/command.hpp): the viewports, scissors
// and the rest a pipeline leaves to the command buffer, each set with its
// set_* method. A base of vkrc::CommandRecorder (so of CommandBuffer),
// included by vkrc/command.hpp; call them on a CommandBuffer, as
// cmd.set_cull_mode(mode).
//
// bind_vertex_buffers2, whose strides may be dynamic, is beside
// bind_vertex_buffers in vkrc/command.hpp. Inline, each one call through the
// device function table, as every recording method.
#pragma once

#include "vkrc/functions.hpp"
#include "vkrc/handle.hpp"

#include "vkrc/detail/span.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {

// Self is the CommandRecorder: each method records through the table and the
// raw handle of Self::recording(*this, who), which checks it holds one.
template <class Self>
class DynamicStateCommands {
public:
    // Viewport 0 and scissor 0 (dynamic in GraphicsPipelineBuilder's
    // pipelines unless dynamic_states replaced them).
    void set_viewport(const VkViewport& viewport) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::set_viewport");
        self.fn_->vkCmdSetViewport(self.cmd_, 0, 1, &viewport);
    }
    void set_scissor(const VkRect2D& scissor) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::set_scissor");
        self.fn_->vkCmdSetScissor(self.cmd_, 0, 1, &scissor);
    }
    // Viewport (depth 0..1) and scissor covering extent.
    void set_viewport_and_scissor(VkExtent2D extent) const VKRC_UNCHECKED_NOEXCEPT {
        Self::recording(*this, "vkrc::CommandBuffer::set_viewport_and_scissor");
        set_viewport({0.0f, 0.0f, static_cast<float>(extent.width), static_cast<float>(extent.height), 0.0f, 1.0f});
        set_scissor({{0, 0}, extent});
    }

    // Dynamic state (Vulkan 1.0): each needs its VK_DYNAMIC_STATE_* in the
    // bound pipeline's dynamic states.
    void set_viewports(std::uint32_t first, Span<const VkViewport> viewports) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::set_viewports");
        self.fn_->vkCmdSetViewport(self.cmd_, first, static_cast<std::uint32_t>(viewports.size()), viewports.data());
    }
    void set_scissors(std::uint32_t first, Span<const VkRect2D> scissors) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::set_scissors");
        self.fn_->vkCmdSetScissor(self.cmd_, first, static_cast<std::uint32_t>(scissors.size()), scissors.data());
    }
    // Other widths than 1.0 need the wideLines feature.
    void set_line_width(float width) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::set_line_width");
        self.fn_->vkCmdSetLineWidth(self.cmd_, width);
    }
    // A clamp other than 0 needs the depthBiasClamp feature.
    void set_depth_bias(float constant_factor, float clamp, float slope_factor) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::set_depth_bias");
        self.fn_->vkCmdSetDepthBias(self.cmd_, constant_factor, clamp, slope_factor);
    }
    void set_blend_constants(const float (&constants)[4]) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::set_blend_constants");
        self.fn_->vkCmdSetBlendConstants(self.cmd_, constants);
    }
    void set_depth_bounds(float min_bounds, float max_bounds) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::set_depth_bounds");
        self.fn_->vkCmdSetDepthBounds(self.cmd_, min_bounds, max_bounds);
    }
    void set_stencil_compare_mask(VkStencilFaceFlags faces, std::uint32_t mask) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::set_stencil_compare_mask");
        self.fn_->vkCmdSetStencilCompareMask(self.cmd_, faces, mask);
    }
    void set_stencil_write_mask(VkStencilFaceFlags faces, std::uint32_t mask) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::set_stencil_write_mask");
        self.fn_->vkCmdSetStencilWriteMask(self.cmd_, faces, mask);
    }
    void set_stencil_reference(VkStencilFaceFlags faces, std::uint32_t reference) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::set_stencil_reference");
        self.fn_->vkCmdSetStencilReference(self.cmd_, faces, reference);
    }

    // Dynamic state (Vulkan 1.3 core, formerly extended dynamic state 1 and 2).
    void set_cull_mode(VkCullModeFlags mode) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::set_cull_mode");
        self.fn_->vkCmdSetCullMode(self.cmd_, mode);
    }
    void set_front_face(VkFrontFace face) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::set_front_face");
        self.fn_->vkCmdSetFrontFace(self.cmd_, face);
    }
    void set_primitive_topology(VkPrimitiveTopology topology) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::set_primitive_topology");
        self.fn_->vkCmdSetPrimitiveTopology(self.cmd_, topology);
    }
    // The viewport and scissor counts are dynamic too (VIEWPORT_WITH_COUNT / SCISSOR_WITH_COUNT).
    void set_viewport_with_count(Span<const VkViewport> viewports) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::set_viewport_with_count");
        self.fn_->vkCmdSetViewportWithCount(self.cmd_, static_cast<std::uint32_t>(viewports.size()), viewports.data());
    }
    void set_scissor_with_count(Span<const VkRect2D> scissors) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::set_scissor_with_count");
        self.fn_->vkCmdSetScissorWithCount(self.cmd_, static_cast<std::uint32_t>(scissors.size()), scissors.data());
    }
    void set_depth_test_enable(bool enable) const VKRC_UNCHECKED_NOEXCEPT {
        set_enable<&DeviceFunctions::vkCmdSetDepthTestEnable>("vkrc::CommandBuffer::set_depth_test_enable", enable);
    }
    void set_depth_write_enable(bool enable) const VKRC_UNCHECKED_NOEXCEPT {
        set_enable<&DeviceFunctions::vkCmdSetDepthWriteEnable>("vkrc::CommandBuffer::set_depth_write_enable", enable);
    }
    void set_depth_compare_op(VkCompareOp op) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::set_depth_compare_op");
        self.fn_->vkCmdSetDepthCompareOp(self.cmd_, op);
    }
    // Enabling needs the depthBounds feature.
    void set_depth_bounds_test_enable(bool enable) const VKRC_UNCHECKED_NOEXCEPT {
        set_enable<&DeviceFunctions::vkCmdSetDepthBoundsTestEnable>("vkrc::CommandBuffer::set_depth_bounds_test_enable",
                                                                    enable);
    }
    void set_stencil_test_enable(bool enable) const VKRC_UNCHECKED_NOEXCEPT {
        set_enable<&DeviceFunctions::vkCmdSetStencilTestEnable>("vkrc::CommandBuffer::set_stencil_test_enable", enable);
    }
    void set_stencil_op(VkStencilFaceFlags faces, VkStencilOp fail_op, VkStencilOp pass_op, VkStencilOp depth_fail_op,
                        VkCompareOp compare_op) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::set_stencil_op");
        self.fn_->vkCmdSetStencilOp(self.cmd_, faces, fail_op, pass_op, depth_fail_op, compare_op);
    }
    void set_rasterizer_discard_enable(bool enable) const VKRC_UNCHECKED_NOEXCEPT {
        set_enable<&DeviceFunctions::vkCmdSetRasterizerDiscardEnable>(
            "vkrc::CommandBuffer::set_rasterizer_discard_enable", enable);
    }
    void set_depth_bias_enable(bool enable) const VKRC_UNCHECKED_NOEXCEPT {
        set_enable<&DeviceFunctions::vkCmdSetDepthBiasEnable>("vkrc::CommandBuffer::set_depth_bias_enable", enable);
    }
    void set_primitive_restart_enable(bool enable) const VKRC_UNCHECKED_NOEXCEPT {
        set_enable<&DeviceFunctions::vkCmdSetPrimitiveRestartEnable>(
            "vkrc::CommandBuffer::set_primitive_restart_enable", enable);
    }

private:
    // The one body of the VkBool32 setters (cmd is the vkCmdSet*Enable
    // member of the table; who names the caller).
    template <auto cmd>
    void set_enable(const char* who, bool enable) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, who);
        (self.fn_->*cmd)(self.cmd_, enable ? VK_TRUE : VK_FALSE);
    }
};

}  // namespace detail

VKRC_END_NAMESPACE
