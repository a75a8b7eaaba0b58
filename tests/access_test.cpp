// Barriers by named use (vkrc/access.hpp): the tables against what the
// Vulkan specification expects of each use, checked at compile time; the
// rendering through them under synchronization validation is in render_test.cpp.
#include <vkrc/vkrc.hpp>

#include <gtest/gtest.h>

namespace {

namespace use = vkrc::use;

constexpr VkPipelineStageFlags2 shader_stages =
    VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_2_TESSELLATION_CONTROL_SHADER_BIT |
    VK_PIPELINE_STAGE_2_TESSELLATION_EVALUATION_SHADER_BIT | VK_PIPELINE_STAGE_2_GEOMETRY_SHADER_BIT |
    VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
constexpr VkPipelineStageFlags2 transfer_stages = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT | VK_PIPELINE_STAGE_2_COPY_BIT |
                                                  VK_PIPELINE_STAGE_2_BLIT_BIT | VK_PIPELINE_STAGE_2_RESOLVE_BIT |
                                                  VK_PIPELINE_STAGE_2_CLEAR_BIT;
constexpr VkPipelineStageFlags2 fragment_tests =
    VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;

// The stages that may perform an access: the specification's "Supported
// access types" table (synchronization2), for the accesses the uses name.
constexpr VkPipelineStageFlags2 stages_supporting(VkAccessFlags2 access) {
    switch (access) {
        case VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT: return VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;
        case VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT:
        case VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT: return fragment_tests;
        case VK_ACCESS_2_SHADER_SAMPLED_READ_BIT:
        case VK_ACCESS_2_SHADER_STORAGE_READ_BIT:
        case VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT:
        case VK_ACCESS_2_UNIFORM_READ_BIT: return shader_stages;
        case VK_ACCESS_2_TRANSFER_READ_BIT:
        case VK_ACCESS_2_TRANSFER_WRITE_BIT: return transfer_stages;
        case VK_ACCESS_2_VERTEX_ATTRIBUTE_READ_BIT: return VK_PIPELINE_STAGE_2_VERTEX_ATTRIBUTE_INPUT_BIT;
        case VK_ACCESS_2_INDEX_READ_BIT: return VK_PIPELINE_STAGE_2_INDEX_INPUT_BIT;
        case VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT: return VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT;
        case VK_ACCESS_2_HOST_READ_BIT:
        case VK_ACCESS_2_HOST_WRITE_BIT: return VK_PIPELINE_STAGE_2_HOST_BIT;
        default: return 0;
    }
}

// VUID-VkImageMemoryBarrier2-srcAccessMask-03900 and its siblings: every
// access bit needs one of its stages in the stage mask; a stage without access
// is an execution dependency only.
constexpr bool valid(const vkrc::Use& u) {
    for (VkAccessFlags2 bit = 1; bit != 0; bit <<= 1)
        if ((u.access & bit) && !(stages_supporting(bit) & u.stage)) return false;
    return true;
}

constexpr vkrc::Use all[] = {use::none,
                             use::colour_attachment_write,
                             use::depth_attachment,
                             use::depth_attachment_read,
                             use::sampled(VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT),
                             use::sampled(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT),
                             use::uniform_read(VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT),
                             use::compute_storage_read,
                             use::compute_storage_write,
                             use::compute_storage_read_write,
                             use::transfer_src,
                             use::transfer_dst,
                             use::vertex_input,
                             use::index_input,
                             use::indirect_read,
                             use::host_read,
                             use::host_write,
                             use::acquired,
                             use::present,
                             use::presented(VK_IMAGE_LAYOUT_GENERAL)};

constexpr bool all_valid() {
    for (const auto& u : all)
        if (!valid(u)) return false;
    return true;
}
static_assert(all_valid(), "a named use pairs an access with a stage that cannot perform it");

// The layouts the specification requires of each image use.
static_assert(use::colour_attachment_write.layout == VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
static_assert(use::depth_attachment.layout == VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
static_assert(use::depth_attachment_read.layout == VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL);
static_assert(use::sampled(VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT).layout == VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
static_assert(use::compute_storage_write.layout == VK_IMAGE_LAYOUT_GENERAL);  // storage images: GENERAL only
static_assert(use::transfer_src.layout == VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
static_assert(use::transfer_dst.layout == VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
static_assert(use::host_read.layout == VK_IMAGE_LAYOUT_GENERAL);  // host image access: GENERAL
static_assert(use::present.layout == VK_IMAGE_LAYOUT_PRESENT_SRC_KHR);
// The acquire semaphore is waited on at the stage the swapchain's Frame names.
static_assert(use::acquired.stage == vkrc::Frame::acquire_stage && use::acquired.layout == VK_IMAGE_LAYOUT_UNDEFINED);
// Writes are the accesses the tables say they are.
static_assert(use::colour_attachment_write.access == VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
static_assert(use::depth_attachment.access ==
              (VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT));
static_assert(use::depth_attachment.stage == fragment_tests);
static_assert(use::discarded(use::transfer_src) == vkrc::Use{VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                                                             VK_ACCESS_2_TRANSFER_READ_BIT, VK_IMAGE_LAYOUT_UNDEFINED});

// The helpers: the barrier's fields come from the two uses, nothing else.
TEST(Access, MemoryBarrierTakesBothScopesFromTheUses) {
    const auto b = vkrc::memory_barrier(use::compute_storage_write, use::host_read);
    EXPECT_EQ(b.sType, VK_STRUCTURE_TYPE_MEMORY_BARRIER_2);
    EXPECT_EQ(b.srcStageMask, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
    EXPECT_EQ(b.srcAccessMask, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    EXPECT_EQ(b.dstStageMask, VK_PIPELINE_STAGE_2_HOST_BIT);
    EXPECT_EQ(b.dstAccessMask, VK_ACCESS_2_HOST_READ_BIT);
}

TEST(Access, AStageMayNotPerformAnotherStagesAccess) {
    // The check above can fail: a colour write in the fragment shader stage is invalid.
    EXPECT_FALSE(valid({VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT}));
    EXPECT_FALSE(valid({VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_HOST_READ_BIT}));
    EXPECT_TRUE(valid(use::sampled(VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT)));
}

}  // namespace
