// Transfer commands of CommandBuffer (vkrc/command.hpp): copies, blits,
// resolves, clears, fills and updates of buffers and images. A base of
// vkrc::CommandRecorder (so of CommandBuffer), included by vkrc/command.hpp;
// call them on a CommandBuffer, as cmd.copy_buffer(src, dst, regions).
//
// Layouts are the images' current ones (TRANSFER_SRC/DST_OPTIMAL or
// GENERAL); regions are read during the call only. Inline, each one call
// through the device function table, as every recording method.
#pragma once

#include "vkrc/handle.hpp"

#include "vkrc/detail/span.hpp"

VKRC_BEGIN_NAMESPACE

namespace detail {
[[noreturn]] void throw_bad_update_buffer(VkDeviceSize offset, VkDeviceSize size);

// Self is the CommandRecorder: each method records through the table and the
// raw handle of Self::recording(*this, who), which checks it holds one.
template <class Self>
class TransferCommands {
public:
    void copy_buffer(Raw<VkBuffer> src, Raw<VkBuffer> dst,
                     Span<const VkBufferCopy> regions) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::copy_buffer");
        self.fn_->vkCmdCopyBuffer(self.cmd_, src, dst, static_cast<std::uint32_t>(regions.size()), regions.data());
    }
    void copy_buffer_to_image(Raw<VkBuffer> src, Raw<VkImage> dst, VkImageLayout dst_layout,
                              Span<const VkBufferImageCopy> regions) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::copy_buffer_to_image");
        self.fn_->vkCmdCopyBufferToImage(self.cmd_, src, dst, dst_layout, static_cast<std::uint32_t>(regions.size()),
                                         regions.data());
    }
    void copy_image_to_buffer(Raw<VkImage> src, VkImageLayout src_layout, Raw<VkBuffer> dst,
                              Span<const VkBufferImageCopy> regions) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::copy_image_to_buffer");
        self.fn_->vkCmdCopyImageToBuffer(self.cmd_, src, src_layout, dst, static_cast<std::uint32_t>(regions.size()),
                                         regions.data());
    }
    void copy_image(Raw<VkImage> src, VkImageLayout src_layout, Raw<VkImage> dst, VkImageLayout dst_layout,
                    Span<const VkImageCopy> regions) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::copy_image");
        self.fn_->vkCmdCopyImage(self.cmd_, src, src_layout, dst, dst_layout,
                                 static_cast<std::uint32_t>(regions.size()), regions.data());
    }
    void blit_image(Raw<VkImage> src, VkImageLayout src_layout, Raw<VkImage> dst, VkImageLayout dst_layout,
                    Span<const VkImageBlit> regions, VkFilter filter = VK_FILTER_LINEAR) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::blit_image");
        self.fn_->vkCmdBlitImage(self.cmd_, src, src_layout, dst, dst_layout,
                                 static_cast<std::uint32_t>(regions.size()), regions.data(), filter);
    }
    // src: multisampled; dst: single-sample, same format.
    void resolve_image(Raw<VkImage> src, VkImageLayout src_layout, Raw<VkImage> dst, VkImageLayout dst_layout,
                       Span<const VkImageResolve> regions) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::resolve_image");
        self.fn_->vkCmdResolveImage(self.cmd_, src, src_layout, dst, dst_layout,
                                    static_cast<std::uint32_t>(regions.size()), regions.data());
    }
    // Outside rendering; the image needs TRANSFER_DST usage.
    void clear_color_image(Raw<VkImage> image, VkImageLayout layout, const VkClearColorValue& color,
                           Span<const VkImageSubresourceRange> ranges) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::clear_color_image");
        self.fn_->vkCmdClearColorImage(self.cmd_, image, layout, &color, static_cast<std::uint32_t>(ranges.size()),
                                       ranges.data());
    }
    void clear_depth_stencil_image(Raw<VkImage> image, VkImageLayout layout, const VkClearDepthStencilValue& value,
                                   Span<const VkImageSubresourceRange> ranges) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::clear_depth_stencil_image");
        self.fn_->vkCmdClearDepthStencilImage(self.cmd_, image, layout, &value,
                                              static_cast<std::uint32_t>(ranges.size()), ranges.data());
    }
    // Inside rendering (a render pass or dynamic rendering).
    void clear_attachments(Span<const VkClearAttachment> attachments,
                           Span<const VkClearRect> rects) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::clear_attachments");
        self.fn_->vkCmdClearAttachments(self.cmd_, static_cast<std::uint32_t>(attachments.size()), attachments.data(),
                                        static_cast<std::uint32_t>(rects.size()), rects.data());
    }
    // dst from offset: size bytes (a multiple of 4, or VK_WHOLE_SIZE) set to the 4-byte word data, repeated.
    void fill_buffer(Raw<VkBuffer> dst, VkDeviceSize offset, VkDeviceSize size,
                     std::uint32_t data) const VKRC_UNCHECKED_NOEXCEPT {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::fill_buffer");
        self.fn_->vkCmdFillBuffer(self.cmd_, dst, offset, size, data);
    }
    // vkCmdUpdateBuffer: size bytes of data, copied into the command buffer at
    // this call (data need not outlive it). size and offset are multiples of
    // 4 and size is at most 65536; with VKRC_RUNTIME_CHECKS, UsageError otherwise.
    void update_buffer(Raw<VkBuffer> dst, VkDeviceSize offset, VkDeviceSize size, const void* data) const {
        const Self& self = Self::recording(*this, "vkrc::CommandBuffer::update_buffer");
#if VKRC_RUNTIME_CHECKS
        if (size == 0 || size > 65536 || size % 4 != 0 || offset % 4 != 0) [[unlikely]] {
            throw_bad_update_buffer(offset, size);
        }
#endif
        self.fn_->vkCmdUpdateBuffer(self.cmd_, dst, offset, size, data);
    }
};

}  // namespace detail

VKRC_END_NAMESPACE
