// Barriers (synchronization2) and queue-family ownership transfers: the
// structs that CommandBuffer::pipeline_barrier (vkrc/command.hpp) records,
// filled in by value. No handles are kept and nothing is recorded here.
#pragma once

#include "vkrc/config.hpp"

#include <vulkan/vulkan_core.h>

#include <cstdint>

VKRC_BEGIN_NAMESPACE

// An image barrier over range (see mip_range and layer_range). Inline: it
// only fills a struct, which the caller's compiler folds into its own stores.
// Each field is named once: a zeroed struct then assigned field by field
// cost the teapot's command stage (three barriers) 47 more instructions
// under GCC 12, which stored most fields twice.
inline VkImageMemoryBarrier2 image_barrier(VkImage image, const VkImageSubresourceRange& range,
                                           VkImageLayout old_layout, VkImageLayout new_layout,
                                           VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                                           VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access) noexcept {
    return {.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2,
            .pNext = nullptr,
            .srcStageMask = src_stage,
            .srcAccessMask = src_access,
            .dstStageMask = dst_stage,
            .dstAccessMask = dst_access,
            .oldLayout = old_layout,
            .newLayout = new_layout,
            .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
            .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
            .image = image,
            .subresourceRange = range};
}
// An image barrier over every mip level and layer of one aspect.
inline VkImageMemoryBarrier2 image_barrier(VkImage image, VkImageLayout old_layout, VkImageLayout new_layout,
                                           VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                                           VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access,
                                           VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT) noexcept {
    return image_barrier(image,
                         {.aspectMask = aspect,
                          .baseMipLevel = 0,
                          .levelCount = VK_REMAINING_MIP_LEVELS,
                          .baseArrayLayer = 0,
                          .layerCount = VK_REMAINING_ARRAY_LAYERS},
                         old_layout, new_layout, src_stage, src_access, dst_stage, dst_access);
}
// A global memory barrier.
inline VkMemoryBarrier2 memory_barrier(VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                                       VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access) noexcept {
    return {.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2,
            .pNext = nullptr,
            .srcStageMask = src_stage,
            .srcAccessMask = src_access,
            .dstStageMask = dst_stage,
            .dstAccessMask = dst_access};
}

// count mip levels from base_level, every layer.
VkImageSubresourceRange mip_range(std::uint32_t base_level, std::uint32_t level_count = 1,
                                  VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT) noexcept;
// count array layers from base_layer, every mip level.
VkImageSubresourceRange layer_range(std::uint32_t base_layer, std::uint32_t layer_count = 1,
                                    VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT) noexcept;
// A buffer barrier over size bytes from offset (VK_WHOLE_SIZE: to the end).
VkBufferMemoryBarrier2 buffer_barrier(VkBuffer buffer, VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                                      VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access,
                                      VkDeviceSize offset = 0, VkDeviceSize size = VK_WHOLE_SIZE) noexcept;

// A queue-family ownership transfer of an EXCLUSIVE image: record release()
// on a queue of src_family, then, after a semaphore, acquire() on a queue of
// dst_family. Vulkan wants both barriers to name the same families, layouts
// and range; one description makes both, so they cannot disagree.
struct ImageOwnershipTransfer {
    // Required.
    VkImage image = VK_NULL_HANDLE;
    // Optional (default every level and layer of the colour aspect).
    VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, VK_REMAINING_MIP_LEVELS, 0, VK_REMAINING_ARRAY_LAYERS};
    // The layout transition that travels with the transfer (equal: none).
    VkImageLayout old_layout = VK_IMAGE_LAYOUT_UNDEFINED;
    VkImageLayout new_layout = VK_IMAGE_LAYOUT_UNDEFINED;
    // Required: the family giving the image up and the one taking it.
    std::uint32_t src_family = VK_QUEUE_FAMILY_IGNORED;
    std::uint32_t dst_family = VK_QUEUE_FAMILY_IGNORED;

    // The barrier after the writes that src_family's queue made (its
    // destination scope is empty: Vulkan ignores it).
    VkImageMemoryBarrier2 release(VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access) const noexcept;
    // The barrier before dst_family's queue uses the image (empty source scope).
    VkImageMemoryBarrier2 acquire(VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access) const noexcept;
};

// The same for an EXCLUSIVE buffer's size bytes from offset (VK_WHOLE_SIZE: to the end).
struct BufferOwnershipTransfer {
    // Required.
    VkBuffer buffer = VK_NULL_HANDLE;
    // Required: the family giving the buffer up and the one taking it.
    std::uint32_t src_family = VK_QUEUE_FAMILY_IGNORED;
    std::uint32_t dst_family = VK_QUEUE_FAMILY_IGNORED;
    // Optional (default the whole buffer).
    VkDeviceSize offset = 0;
    VkDeviceSize size = VK_WHOLE_SIZE;

    VkBufferMemoryBarrier2 release(VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access) const noexcept;
    VkBufferMemoryBarrier2 acquire(VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access) const noexcept;
};

VKRC_END_NAMESPACE
