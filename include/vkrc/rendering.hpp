// What dynamic rendering and secondary command buffers are begun with
// (CommandBuffer::begin_rendering and begin_secondary, vkrc/command.hpp).
#pragma once

#include "vkrc/pipeline.hpp"

#include "vkrc/detail/span.hpp"

VKRC_BEGIN_NAMESPACE

// What a secondary command buffer inherits (VkCommandBufferInheritanceInfo,
// with VkCommandBufferInheritanceRenderingInfo for dynamic rendering). Leave
// render_pass empty and color_formats empty for secondaries used outside
// rendering; set either for RENDER_PASS_CONTINUE secondaries.
// Every member is optional and read during begin_secondary() (the command buffer keeps no reference).
struct CommandBufferInheritance {
    // A render pass; subpass and framebuffer (empty: not known) go with it.
    RenderPass render_pass{};
    std::uint32_t subpass = 0;
    Framebuffer framebuffer{};
    // Dynamic rendering, without render_pass: need not outlive begin_secondary().
    Span<const VkFormat> color_formats{};
    VkFormat depth_format = VK_FORMAT_UNDEFINED;
    VkFormat stencil_format = VK_FORMAT_UNDEFINED;
    VkSampleCountFlagBits rasterization_samples = VK_SAMPLE_COUNT_1_BIT;
};

// One attachment of dynamic rendering (VkRenderingAttachmentInfo).
// image_view: view.vk() of an ImageView that lives until the work is submitted.
struct RenderingAttachment {
    // Required.
    VkImageView image_view = VK_NULL_HANDLE;
    // Optional (default colour attachment optimal; set it for depth).
    VkImageLayout image_layout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    // Optional (default clear, then store).
    VkAttachmentLoadOp load_op = VK_ATTACHMENT_LOAD_OP_CLEAR;
    VkAttachmentStoreOp store_op = VK_ATTACHMENT_STORE_OP_STORE;
    // Used with load_op CLEAR (default zero).
    VkClearValue clear_value{};
    // Optional multisample resolve: NONE (the default) resolves nothing;
    // otherwise resolve_image_view (a single-sample view that lives until the
    // work is submitted) receives the resolved image, in resolve_image_layout.
    VkResolveModeFlagBits resolve_mode = VK_RESOLVE_MODE_NONE;
    VkImageView resolve_image_view = VK_NULL_HANDLE;
    VkImageLayout resolve_image_layout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
};

// VkRenderingInfo. At most max_color_attachments colour attachments.
// Read during begin_rendering(): the span and pointers need not outlive the call.
struct RenderingInfo {
    static constexpr std::uint32_t max_color_attachments = 8;
    // Required (the default is empty).
    VkRect2D render_area{};
    // Optional (empty: none).
    Span<const RenderingAttachment> color_attachments{};
    // Optional (null: none).
    const RenderingAttachment* depth_attachment = nullptr;
    const RenderingAttachment* stencil_attachment = nullptr;
    // Optional (default none).
    VkRenderingFlags flags = 0;
    // Optional (default 1).
    std::uint32_t layer_count = 1;
    // Optional multiview mask (0: no multiview; needs the multiview feature).
    std::uint32_t view_mask = 0;
    // Optional pNext chain of VkRenderingInfo; must live through the call.
    const void* next = nullptr;
};

namespace detail {
[[noreturn]] void throw_too_many_color_attachments(std::size_t count);

// begin_rendering's conversion: a function rather than a lambda, and an
// index loop rather than span iterators, because each closure type and
// iterator instantiation costs every includer's compile (bench/header_cost).
inline VkRenderingAttachmentInfo rendering_attachment_info(const RenderingAttachment& a) noexcept {
    return {.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
            .pNext = nullptr,
            .imageView = a.image_view,
            .imageLayout = a.image_layout,
            .resolveMode = a.resolve_mode,
            .resolveImageView = a.resolve_image_view,
            .resolveImageLayout = a.resolve_image_layout,
            .loadOp = a.load_op,
            .storeOp = a.store_op,
            .clearValue = a.clear_value};
}
}  // namespace detail

VKRC_END_NAMESPACE
