// Mipmap generation on the GPU: blits recorded into a command buffer.
#pragma once

#include "vkrc/command.hpp"

VKRC_BEGIN_NAMESPACE

// What generate_mipmaps starts from and leaves behind.
struct MipmapInfo {
    // Level 0's layout now and the writes that filled it (an upload's copy by default).
    VkImageLayout base_layout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    VkPipelineStageFlags2 src_stage = VK_PIPELINE_STAGE_2_COPY_BIT;
    VkAccessFlags2 src_access = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    // Every level's layout afterwards, and who reads it next.
    VkImageLayout final_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    VkPipelineStageFlags2 dst_stage = VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;
    VkAccessFlags2 dst_access = VK_ACCESS_2_SHADER_SAMPLED_READ_BIT;
    VkFilter filter = VK_FILTER_LINEAR;
    // The layers to process (VK_REMAINING_ARRAY_LAYERS: to the last).
    std::uint32_t base_layer = 0;
    std::uint32_t layer_count = VK_REMAINING_ARRAY_LAYERS;
};

// Records the blits that fill mip levels 1.. of image from level 0, each
// level from the one above, with the barriers between them; the other
// levels' old contents are discarded. Throws UsageError when the image lacks
// TRANSFER_SRC and TRANSFER_DST usage, is multisampled, its format cannot be
// blitted (or linearly filtered, for VK_FILTER_LINEAR) with optimal tiling,
// the command buffer's queue family has no graphics, or the layers are out of range.
void generate_mipmaps(const CommandBuffer& cmd, const Image& image, const MipmapInfo& info = {});

VKRC_END_NAMESPACE
