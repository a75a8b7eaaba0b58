// Issue 14's commands: blit, mipmaps, resolve, clears, update/copy regions,
// indirect work, queries, debug-utils labels and the barrier helpers, each
// read back and checked (validation messages fail the test, as everywhere).
#include "support/features.hpp"
#include "support/vk_test.hpp"

#include "shaders/fill_pattern.comp.h"
#include "shaders/push_color.frag.h"
#include "shaders/rect.vert.h"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <span>
#include <string>
#include <vector>

namespace {

using vkrc_test::VulkanTest;
using OneShot = vkrc_test::OneShotCommands;
using vkrc_test::Rgba;
constexpr VkFormat rgba8 = VK_FORMAT_R8G8B8A8_UNORM;

struct RectPush {
    float color[4];
    float bounds[4];  // x0 y0 x1 y1, NDC
    float depth;
};

vkrc::Buffer host_buffer(const vkrc::Device& device, VkDeviceSize bytes, VkBufferUsageFlags usage,
                         vkrc::MemoryUsage memory = vkrc::MemoryUsage::readback) {
    return vkrc::Buffer::create(device, {.size = bytes, .usage = usage, .memory = {.usage = memory}});
}

vkrc::Image color_image(const vkrc::Device& device, std::uint32_t size, VkImageUsageFlags usage,
                        std::uint32_t mip_levels = 1, VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT,
                        std::uint32_t layers = 1) {
    return vkrc::Image::create(device, {.format = rgba8,
                                        .extent = {size, size, 1},
                                        .mip_levels = mip_levels,
                                        .array_layers = layers,
                                        .samples = samples,
                                        .usage = usage});
}

VkBufferImageCopy level_region(std::uint32_t level, std::uint32_t extent, std::uint32_t layer = 0,
                               std::uint32_t layers = 1, VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT) {
    VkBufferImageCopy r{};
    r.imageSubresource = {aspect, level, layer, layers};
    r.imageExtent = {extent, extent, 1};
    return r;
}

// Copies a region of image (in TRANSFER_SRC_OPTIMAL) into pixels and makes it host-visible.
void record_readback(const vkrc::CommandBuffer& cmd, const vkrc::Image& image, const vkrc::Buffer& pixels,
                     const VkBufferImageCopy& region) {
    cmd.copy_image_to_buffer(image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, pixels, std::span(&region, 1));
    auto to_host = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                        VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
}

Rgba texel(const vkrc::Buffer& pixels, std::uint32_t width, std::uint32_t x, std::uint32_t y) {
    return pixels.allocation().read_value<Rgba>((y * width + x) * 4);
}

void transition(const vkrc::CommandBuffer& cmd, const vkrc::Image& image, VkImageLayout from, VkImageLayout to,
                VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access, VkPipelineStageFlags2 dst_stage,
                VkAccessFlags2 dst_access) {
    auto b = vkrc::image_barrier(image.vk(), from, to, src_stage, src_access, dst_stage, dst_access);
    cmd.pipeline_barrier({}, {}, std::span(&b, 1));
}

constexpr auto copy_stage = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT;
constexpr auto transfer_rw = VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT;

// Uploads rgba (size*size texels) into level 0 of image, left in TRANSFER_DST_OPTIMAL.
vkrc::Buffer record_upload(const vkrc::CommandBuffer& cmd, const vkrc::Image& image, const std::vector<Rgba>& rgba,
                           std::uint32_t size) {
    auto staging =
        host_buffer(image.device(), rgba.size() * 4, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vkrc::MemoryUsage::upload);
    staging.allocation().write(0, std::span(rgba));
    transition(cmd, image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
               copy_stage, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    auto region = level_region(0, size);
    cmd.copy_buffer_to_image(staging, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, std::span(&region, 1));
    return staging;  // the caller keeps it until the work is done
}

bool near(Rgba got, Rgba want, int tolerance) {
    for (int c = 0; c < 4; ++c) {
        if (std::abs(int(got[c]) - int(want[c])) > tolerance) return false;
    }
    return true;
}

::testing::AssertionResult texel_near(Rgba got, Rgba want, int tolerance) {
    if (near(got, want, tolerance)) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "got " << int(got[0]) << "," << int(got[1]) << "," << int(got[2]) << ","
                                         << int(got[3]) << " want " << int(want[0]) << "," << int(want[1]) << ","
                                         << int(want[2]) << "," << int(want[3]) << " +-" << tolerance;
}

// Clear

TEST_F(VulkanTest, ClearColorImageLayersAndDepthStencilImage) {
    constexpr std::uint32_t size = 4;
    auto image = color_image(device, size, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, 1,
                             VK_SAMPLE_COUNT_1_BIT, 2);
    auto depth =
        vkrc::Image::create(device, {.format = VK_FORMAT_D32_SFLOAT,
                                     .extent = {size, size, 1},
                                     .usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
    auto pixels = host_buffer(device, size * size * 4 * 3, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    OneShot s(queue);
    // One barrier per layer range: the helpers cover what image_barrier's whole-image default cannot.
    const VkImageMemoryBarrier2 in[] = {
        vkrc::image_barrier(image.vk(), vkrc::layer_range(0), VK_IMAGE_LAYOUT_UNDEFINED,
                            VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0, copy_stage,
                            VK_ACCESS_2_TRANSFER_WRITE_BIT),
        vkrc::image_barrier(image.vk(), vkrc::layer_range(1), VK_IMAGE_LAYOUT_UNDEFINED,
                            VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0, copy_stage,
                            VK_ACCESS_2_TRANSFER_WRITE_BIT),
        vkrc::image_barrier(depth.vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                            VK_PIPELINE_STAGE_2_NONE, 0, copy_stage, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                            VK_IMAGE_ASPECT_DEPTH_BIT)};
    s.cmd.pipeline_barrier({}, {}, in);
    const auto layer0 = vkrc::layer_range(0), layer1 = vkrc::layer_range(1);
    s.cmd.clear_color_image(image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, {{1.0f, 0.0f, 0.0f, 1.0f}},
                            std::span(&layer0, 1));
    s.cmd.clear_color_image(image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, {{0.0f, 1.0f, 0.0f, 1.0f}},
                            std::span(&layer1, 1));
    const VkImageSubresourceRange depth_range{VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
    s.cmd.clear_depth_stencil_image(depth, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, {0.25f, 0},
                                    std::span(&depth_range, 1));
    transition(s.cmd, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, copy_stage,
               VK_ACCESS_2_TRANSFER_WRITE_BIT, copy_stage, VK_ACCESS_2_TRANSFER_READ_BIT);
    auto d = vkrc::image_barrier(depth.vk(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                 copy_stage, VK_ACCESS_2_TRANSFER_WRITE_BIT, copy_stage, VK_ACCESS_2_TRANSFER_READ_BIT,
                                 VK_IMAGE_ASPECT_DEPTH_BIT);
    s.cmd.pipeline_barrier({}, {}, std::span(&d, 1));
    record_readback(s.cmd, image, pixels, level_region(0, size, 0, 2));
    auto depth_region = level_region(0, size, 0, 1, VK_IMAGE_ASPECT_DEPTH_BIT);
    depth_region.bufferOffset = size * size * 4 * 2;
    record_readback(s.cmd, depth, pixels, depth_region);
    s.run(queue);
    EXPECT_EQ(texel(pixels, size, 3, 3), (Rgba{255, 0, 0, 255}));
    EXPECT_EQ(texel(pixels, size, 3, 3 + size), (Rgba{0, 255, 0, 255}));  // layer 1 follows layer 0
    EXPECT_EQ(pixels.allocation().read_value<float>(size * size * 4 * 2 + 5 * 4), 0.25f);
}

// The rect pipeline of render_test, drawing into one RGBA8 target by dynamic rendering.
vkrc::GraphicsPipeline rect_pipeline(const vkrc::Device& device,
                                     VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT) {
    auto layout = vkrc::PipelineLayout::create(
        device,
        {.push_constant_ranges = {{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(RectPush)}}});
    return vkrc::GraphicsPipelineBuilder(layout)
        .shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::rect_vert))
        .shader(VK_SHADER_STAGE_FRAGMENT_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::push_color_frag))
        .samples(samples)
        .rendering(std::array{rgba8})
        .build();
}

void push_rect(const vkrc::CommandBuffer& cmd, const vkrc::Pipeline& pipeline, const RectPush& rect) {
    cmd.push_constants(pipeline.layout(), VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, rect);
}

constexpr auto attachment_stage = VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;
constexpr auto attachment_write = VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT;

// Begins dynamic rendering into image (cleared to clear), after moving it to COLOR_ATTACHMENT_OPTIMAL.
void begin_color(const vkrc::CommandBuffer& cmd, const vkrc::Image& image, const vkrc::ImageView& view,
                 VkClearColorValue clear, std::uint32_t size, const vkrc::RenderingAttachment* resolve = nullptr) {
    transition(cmd, image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
               VK_PIPELINE_STAGE_2_NONE, 0, attachment_stage, attachment_write);
    vkrc::RenderingAttachment color{.image_view = view.vk()};
    color.clear_value.color = clear;
    if (resolve) {
        color.resolve_mode = resolve->resolve_mode;
        color.resolve_image_view = resolve->resolve_image_view;
        color.resolve_image_layout = resolve->resolve_image_layout;
    }
    cmd.begin_rendering({.render_area = {{0, 0}, {size, size}}, .color_attachments = std::span(&color, 1)});
    cmd.set_viewport_and_scissor({size, size});
}

void end_color_for_copy(const vkrc::CommandBuffer& cmd, const vkrc::Image& image) {
    cmd.end_rendering();
    transition(cmd, image, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
               attachment_stage, attachment_write, copy_stage, VK_ACCESS_2_TRANSFER_READ_BIT);
}

TEST_F(VulkanTest, ClearAttachmentsInsideDynamicRendering) {
    constexpr std::uint32_t size = 8;
    auto image = color_image(device, size, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    auto view = vkrc::ImageView::create(image);
    auto pixels = host_buffer(device, size * size * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    OneShot s(queue);
    begin_color(s.cmd, image, view, {{1.0f, 0.0f, 0.0f, 1.0f}}, size);
    VkClearAttachment clear{VK_IMAGE_ASPECT_COLOR_BIT, 0, {}};
    clear.clearValue.color = {{0.0f, 0.0f, 1.0f, 1.0f}};
    const VkClearRect left_half{{{0, 0}, {size / 2, size}}, 0, 1};
    s.cmd.clear_attachments(std::span(&clear, 1), std::span(&left_half, 1));
    end_color_for_copy(s.cmd, image);
    record_readback(s.cmd, image, pixels, level_region(0, size));
    s.run(queue);
    EXPECT_EQ(texel(pixels, size, 1, 5), (Rgba{0, 0, 255, 255}));
    EXPECT_EQ(texel(pixels, size, 6, 5), (Rgba{255, 0, 0, 255}));
}

// Blit

std::vector<Rgba> gradient(std::uint32_t size) {
    std::vector<Rgba> out;
    for (std::uint32_t y = 0; y < size; ++y) {
        for (std::uint32_t x = 0; x < size; ++x) {
            out.push_back({std::uint8_t(x * 16), std::uint8_t(y * 16), std::uint8_t((x + y) % 2 ? 255 : 0), 255});
        }
    }
    return out;
}

TEST_F(VulkanTest, BlitScalesUpWithNearestFilter) {
    auto src = color_image(device, 2, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    auto dst = color_image(device, 4, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    auto pixels = host_buffer(device, 4 * 4 * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    OneShot s(queue);
    auto staging = record_upload(s.cmd, src, gradient(2), 2);
    transition(s.cmd, src, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, copy_stage,
               VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_BLIT_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    transition(s.cmd, dst, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
               VK_PIPELINE_STAGE_2_BLIT_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    VkImageBlit region{};
    region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.srcOffsets[1] = {2, 2, 1};
    region.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.dstOffsets[1] = {4, 4, 1};
    s.cmd.blit_image(src, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, dst, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                     std::span(&region, 1), VK_FILTER_NEAREST);
    transition(s.cmd, dst, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
               VK_PIPELINE_STAGE_2_BLIT_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, copy_stage, VK_ACCESS_2_TRANSFER_READ_BIT);
    record_readback(s.cmd, dst, pixels, level_region(0, 4));
    s.run(queue);
    const auto source = gradient(2);
    for (std::uint32_t y = 0; y < 4; ++y) {
        for (std::uint32_t x = 0; x < 4; ++x) {
            EXPECT_EQ(texel(pixels, 4, x, y), source[(y / 2) * 2 + x / 2]) << x << "," << y;
        }
    }
}

// Copy image to image with regions, and update_buffer.
TEST_F(VulkanTest, CopyImageRegionsAndUpdateBuffer) {
    auto src = color_image(device, 4, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    auto dst = color_image(device, 4, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    auto pixels = host_buffer(device, 4 * 4 * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    auto words = host_buffer(device, 16, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    OneShot s(queue);
    auto staging = record_upload(s.cmd, src, gradient(4), 4);
    transition(s.cmd, src, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, copy_stage,
               VK_ACCESS_2_TRANSFER_WRITE_BIT, copy_stage, VK_ACCESS_2_TRANSFER_READ_BIT);
    transition(s.cmd, dst, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
               copy_stage, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    const VkImageSubresourceRange whole{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    s.cmd.clear_color_image(dst, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, {}, std::span(&whole, 1));
    transition(s.cmd, dst, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, copy_stage,
               VK_ACCESS_2_TRANSFER_WRITE_BIT, copy_stage, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    // The top-left 2x2 of src lands at (2, 2) in dst.
    VkImageCopy region{};
    region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.dstSubresource = region.srcSubresource;
    region.dstOffset = {2, 2, 0};
    region.extent = {2, 2, 1};
    s.cmd.copy_image(src, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, dst, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                     std::span(&region, 1));
    transition(s.cmd, dst, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, copy_stage,
               VK_ACCESS_2_TRANSFER_WRITE_BIT, copy_stage, VK_ACCESS_2_TRANSFER_READ_BIT);
    record_readback(s.cmd, dst, pixels, level_region(0, 4));
    const std::uint32_t values[] = {7, 11};
    s.cmd.update_buffer(words, 4, sizeof values, values);
    auto to_host = vkrc::buffer_barrier(words.vk(), copy_stage, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                        VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    s.cmd.pipeline_barrier({}, std::span(&to_host, 1), {});
    s.run(queue);
    const auto source = gradient(4);
    EXPECT_EQ(texel(pixels, 4, 0, 0), (Rgba{0, 0, 0, 0}));
    EXPECT_EQ(texel(pixels, 4, 2, 2), source[0]);
    EXPECT_EQ(texel(pixels, 4, 3, 3), source[5]);
    EXPECT_EQ(words.allocation().read_value<std::uint32_t>(4), 7u);
    EXPECT_EQ(words.allocation().read_value<std::uint32_t>(8), 11u);
}

#if VKRC_RUNTIME_CHECKS
TEST_F(VulkanTest, UpdateBufferRejectsSizesVulkanForbids) {
    auto words = host_buffer(device, 16, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    OneShot s(queue);
    const std::uint32_t value = 1;
    EXPECT_THROW(s.cmd.update_buffer(words, 0, 3, &value), vkrc::UsageError);
    EXPECT_THROW(s.cmd.update_buffer(words, 2, 4, &value), vkrc::UsageError);
    EXPECT_THROW(s.cmd.update_buffer(words, 0, 0, &value), vkrc::UsageError);
    s.cmd.end();
}
#endif

// Mipmaps

TEST_F(VulkanTest, MipmapsAverageEachLevelFromTheOneAbove) {
    constexpr std::uint32_t size = 16, levels = 5;
    auto image = color_image(device, size, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, levels);
    auto level1 = host_buffer(device, 8 * 8 * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    auto last = host_buffer(device, 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    OneShot s(queue);
    const auto source = gradient(size);
    auto staging = record_upload(s.cmd, image, source, size);
    vkrc::generate_mipmaps(s.cmd, image,
                           {.final_layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                            .dst_stage = copy_stage,
                            .dst_access = VK_ACCESS_2_TRANSFER_READ_BIT});
    record_readback(s.cmd, image, level1, level_region(1, 8));
    record_readback(s.cmd, image, last, level_region(levels - 1, 1));
    s.run(queue);
    for (std::uint32_t y = 0; y < 8; ++y) {
        for (std::uint32_t x = 0; x < 8; ++x) {
            int sum[4] = {};
            for (std::uint32_t i = 0; i < 4; ++i) {
                const Rgba t = source[(2 * y + i / 2) * size + 2 * x + i % 2];
                for (int c = 0; c < 4; ++c) sum[c] += t[c];
            }
            const Rgba want{std::uint8_t(sum[0] / 4), std::uint8_t(sum[1] / 4), std::uint8_t(sum[2] / 4), 255};
            EXPECT_TRUE(texel_near(texel(level1, 8, x, y), want, 1)) << "level 1 texel " << x << "," << y;
        }
    }
    // The 1x1 level is the mean of level 0 (rounding of four halvings aside).
    EXPECT_TRUE(texel_near(texel(last, 1, 0, 0), Rgba{120, 120, 128, 255}, 3));
}

TEST_F(VulkanTest, MipmapsRejectImagesTheyCannotBlit) {
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    auto no_src = color_image(device, 8, VK_IMAGE_USAGE_TRANSFER_DST_BIT, 4);
    EXPECT_THROW(vkrc::generate_mipmaps(cmd, no_src), vkrc::UsageError);
    auto ok = color_image(device, 8, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, 4);
    EXPECT_THROW(vkrc::generate_mipmaps(cmd, ok, {.base_layout = VK_IMAGE_LAYOUT_UNDEFINED}), vkrc::UsageError);
    EXPECT_THROW(vkrc::generate_mipmaps(cmd, ok, {.base_layer = 1}), vkrc::UsageError);
    EXPECT_THROW(vkrc::generate_mipmaps(cmd, vkrc::Image{}), vkrc::UsageError);
}

TEST_F(VulkanTest, BarrierHelpersForMipRangesAndOwnership) {
    auto image = color_image(device, 8, VK_IMAGE_USAGE_TRANSFER_DST_BIT, 4);
    auto buffer = host_buffer(device, 64, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    const auto mips = vkrc::mip_range(1, 2);
    EXPECT_EQ(mips.baseMipLevel, 1u);
    EXPECT_EQ(mips.levelCount, 2u);
    EXPECT_EQ(mips.layerCount, VK_REMAINING_ARRAY_LAYERS);
    const std::uint32_t family = queue.family_index();
    const vkrc::ImageOwnershipTransfer image_transfer{.image = image.vk(),
                                                      .range = mips,
                                                      .old_layout = VK_IMAGE_LAYOUT_GENERAL,
                                                      .new_layout = VK_IMAGE_LAYOUT_GENERAL,
                                                      .src_family = family,
                                                      .dst_family = family};
    auto release = image_transfer.release(copy_stage, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    EXPECT_EQ(release.dstStageMask, VK_PIPELINE_STAGE_2_NONE);
    EXPECT_EQ(release.srcQueueFamilyIndex, family);
    auto acquire = image_transfer.acquire(copy_stage, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    EXPECT_EQ(acquire.srcStageMask, VK_PIPELINE_STAGE_2_NONE);
    // Both halves carry the same image, range, layouts and families.
    EXPECT_EQ(acquire.image, release.image);
    EXPECT_EQ(acquire.subresourceRange.baseMipLevel, 1u);
    EXPECT_EQ(acquire.oldLayout, release.oldLayout);
    EXPECT_EQ(acquire.dstQueueFamilyIndex, release.dstQueueFamilyIndex);
    const vkrc::BufferOwnershipTransfer buffer_transfer{
        .buffer = buffer.vk(), .src_family = family, .dst_family = family};
    auto buffer_release = buffer_transfer.release(copy_stage, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    auto buffer_acquire = buffer_transfer.acquire(copy_stage, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    EXPECT_EQ(buffer_acquire.dstQueueFamilyIndex, family);
    EXPECT_EQ(buffer_acquire.size, VK_WHOLE_SIZE);
    // With one family (lavapipe has one) the pair is a plain barrier; recorded
    // for the validation layer to check the structures.
    OneShot s(queue);
    auto to_general = vkrc::image_barrier(image.vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL,
                                          VK_PIPELINE_STAGE_2_NONE, 0, copy_stage, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    s.cmd.pipeline_barrier({}, {}, std::span(&to_general, 1));
    s.cmd.pipeline_barrier({}, std::span(&buffer_release, 1), std::span(&release, 1));
    s.cmd.pipeline_barrier({}, std::span(&buffer_acquire, 1), std::span(&acquire, 1));
    s.run(queue);
}

// Resolve

// Draws a red rect over a black 4x MSAA target whose right edge cuts pixel 1
// in half (NDC -0.25 at 4 pixels across is x = 1.5), so two of the standard
// sample locations are covered there; the resolve averages them.
void draw_half_covered(const vkrc::CommandBuffer& cmd, const vkrc::Pipeline& pipeline) {
    cmd.bind_pipeline(pipeline);
    push_rect(cmd, pipeline, {{1, 0, 0, 1}, {-1.0f, -1.0f, -0.25f, 1.0f}, 0.0f});
    cmd.draw(6);
}

void expect_half_covered(const vkrc::Buffer& pixels) {
    EXPECT_EQ(texel(pixels, 4, 0, 2), (Rgba{255, 0, 0, 255}));
    EXPECT_TRUE(texel_near(texel(pixels, 4, 1, 2), Rgba{128, 0, 0, 255}, 1));
    EXPECT_EQ(texel(pixels, 4, 3, 2), (Rgba{0, 0, 0, 255}));
}

TEST_F(VulkanTest, ResolveAttachmentOfDynamicRendering) {
    constexpr std::uint32_t size = 4;
    auto msaa = color_image(device, size, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, 1, VK_SAMPLE_COUNT_4_BIT);
    auto single = color_image(device, size, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    auto msaa_view = vkrc::ImageView::create(msaa);
    auto single_view = vkrc::ImageView::create(single);
    auto pipeline = rect_pipeline(device, VK_SAMPLE_COUNT_4_BIT);
    auto pixels = host_buffer(device, size * size * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    OneShot s(queue);
    transition(s.cmd, single, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
               VK_PIPELINE_STAGE_2_NONE, 0, attachment_stage, attachment_write);
    const vkrc::RenderingAttachment resolve{.resolve_mode = VK_RESOLVE_MODE_AVERAGE_BIT,
                                            .resolve_image_view = single_view.vk()};
    begin_color(s.cmd, msaa, msaa_view, {{0, 0, 0, 1}}, size, &resolve);
    draw_half_covered(s.cmd, pipeline);
    end_color_for_copy(s.cmd, single);
    record_readback(s.cmd, single, pixels, level_region(0, size));
    s.run(queue);
    expect_half_covered(pixels);
}

TEST_F(VulkanTest, ResolveImageAveragesSamples) {
    constexpr std::uint32_t size = 4;
    auto msaa = color_image(device, size, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, 1,
                            VK_SAMPLE_COUNT_4_BIT);
    auto single = color_image(device, size, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    auto msaa_view = vkrc::ImageView::create(msaa);
    auto pipeline = rect_pipeline(device, VK_SAMPLE_COUNT_4_BIT);
    auto pixels = host_buffer(device, size * size * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    OneShot s(queue);
    begin_color(s.cmd, msaa, msaa_view, {{0, 0, 0, 1}}, size);
    draw_half_covered(s.cmd, pipeline);
    end_color_for_copy(s.cmd, msaa);
    transition(s.cmd, single, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE,
               0, VK_PIPELINE_STAGE_2_RESOLVE_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    VkImageResolve region{};
    region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.dstSubresource = region.srcSubresource;
    region.extent = {size, size, 1};
    s.cmd.resolve_image(msaa, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, single, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                        std::span(&region, 1));
    transition(s.cmd, single, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
               VK_PIPELINE_STAGE_2_RESOLVE_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, copy_stage,
               VK_ACCESS_2_TRANSFER_READ_BIT);
    record_readback(s.cmd, single, pixels, level_region(0, size));
    s.run(queue);
    expect_half_covered(pixels);
}

// Indirect

// A device with the given 1.0 and 1.2 features on (the fixture's has none).
vkrc::Device device_with(const vkrc::PhysicalDevice& physical, const VkPhysicalDeviceFeatures& features,
                         const VkPhysicalDeviceVulkan12Features& features12 = {}) {
    vkrc::DeviceCreateInfo info;
    info.enabled_features = features;
    info.vulkan12_features = features12;
    return vkrc::Device::create(physical, info);
}

struct SupportedFeatures {
    VkPhysicalDeviceFeatures f10{};
    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    explicit SupportedFeatures(const vkrc::PhysicalDevice& physical) {
        VkPhysicalDeviceFeatures2 f{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f12};
        physical.fn().vkGetPhysicalDeviceFeatures2(physical.vk(), &f);
        f10 = f.features;
        f12.pNext = nullptr;
    }
};

// Draws rects from indirect commands into an 8x8 target; returns the pixels.
struct IndirectScene {
    static constexpr std::uint32_t size = 8;
    vkrc::Image image;
    vkrc::ImageView view;
    vkrc::GraphicsPipeline pipeline;
    vkrc::Buffer pixels;
    explicit IndirectScene(const vkrc::Device& device)
        : image(color_image(device, size, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT)),
          view(vkrc::ImageView::create(image)),
          pipeline(rect_pipeline(device)),
          pixels(host_buffer(device, size * size * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT)) {}
    void begin(const vkrc::CommandBuffer& cmd) const {
        begin_color(cmd, image, view, {{0, 0, 0, 1}}, size);
        cmd.bind_pipeline(pipeline);
        push_rect(cmd, pipeline, {{0, 1, 0, 1}, {-1.0f, -1.0f, 1.0f, 1.0f}, 0.0f});
    }
    void end(const vkrc::CommandBuffer& cmd) const {
        end_color_for_copy(cmd, image);
        record_readback(cmd, image, pixels, level_region(0, size));
    }
};

vkrc::Buffer indirect_buffer(const vkrc::Device& device, const void* data, std::size_t bytes,
                             VkBufferUsageFlags usage = VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT) {
    auto b =
        vkrc::Buffer::create(device, {.size = bytes, .usage = usage, .memory = {.usage = vkrc::MemoryUsage::upload}});
    b.allocation().write(0, std::span(static_cast<const std::byte*>(data), bytes));
    return b;
}

constexpr Rgba green{0, 255, 0, 255}, black{0, 0, 0, 255};

TEST_F(VulkanTest, IndirectDrawDrawIndexedAndDispatch) {
    IndirectScene scene(device);
    // The second command draws the rect's 6 vertices (one draw per call:
    // more needs the multiDrawIndirect feature).
    const VkDrawIndirectCommand draws[] = {{0, 1, 0, 0}, {6, 1, 0, 0}};
    auto draw_args = indirect_buffer(device, draws, sizeof draws);
    OneShot s(queue);
    scene.begin(s.cmd);
    s.cmd.draw_indirect(draw_args, sizeof(VkDrawIndirectCommand), 1);
    scene.end(s.cmd);
    s.run(queue);
    EXPECT_EQ(texel(scene.pixels, 8, 4, 4), green);

    // Indexed: the indices 0..5 of the rect, from an index buffer.
    const std::uint32_t indices[] = {0, 1, 2, 3, 4, 5};
    auto index_buffer = indirect_buffer(device, indices, sizeof indices, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
    const VkDrawIndexedIndirectCommand indexed{6, 1, 0, 0, 0};
    auto indexed_args = indirect_buffer(device, &indexed, sizeof indexed);
    OneShot t(queue);
    scene.begin(t.cmd);
    t.cmd.bind_index_buffer(index_buffer);
    t.cmd.draw_indexed_indirect(indexed_args, 0, 1);
    scene.end(t.cmd);
    t.run(queue);
    EXPECT_EQ(texel(scene.pixels, 8, 7, 0), green);
}

TEST_F(VulkanTest, IndirectDispatchWritesThePattern) {
    constexpr std::uint32_t count = 256, seed = 5;
    auto target = host_buffer(device, count * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    auto set_layout =
        vkrc::DescriptorSetLayout::create(device, {.bindings = {{.binding = 0,
                                                                 .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                                                 .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT}}});
    auto layout = vkrc::PipelineLayout::create(
        device, {.set_layouts = {set_layout}, .push_constant_ranges = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, 8}}});
    auto pipeline =
        vkrc::ComputePipeline::create(layout, vkrc::ShaderModule::create(device, vkrc_shaders::fill_pattern_comp));
    auto descriptors =
        vkrc::DescriptorPool::create(device, {.max_sets = 1, .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
    auto set = descriptors.allocate(set_layout);
    set.write_buffer(0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, target);
    const VkDispatchIndirectCommand groups{count / 64, 1, 1};
    auto args = indirect_buffer(device, &groups, sizeof groups);
    OneShot s(queue);
    s.cmd.bind_pipeline(pipeline);
    s.cmd.bind_descriptor_set(pipeline, 0, set);
    const std::uint32_t params[] = {count, seed};
    s.cmd.push_constants(layout, VK_SHADER_STAGE_COMPUTE_BIT, params);
    s.cmd.dispatch_indirect(args);
    auto to_host =
        vkrc::buffer_barrier(target.vk(), VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                             VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    s.cmd.pipeline_barrier({}, std::span(&to_host, 1), {});
    s.run(queue);
    EXPECT_EQ(target.allocation().read_value<std::uint32_t>(4 * (count - 1)), ((count - 1) * 2654435761u) ^ seed);
}

TEST_F(VulkanTest, IndirectCountDrawsUpToTheCountInTheBuffer) {
    SupportedFeatures supported(physical_device);
    if (!supported.f12.drawIndirectCount) GTEST_SKIP() << "the device lacks drawIndirectCount (Vulkan 1.2)";
    VkPhysicalDeviceVulkan12Features f12{};
    f12.drawIndirectCount = VK_TRUE;
    auto dev = device_with(physical_device, {}, f12);
    auto q = dev.default_queue();
    IndirectScene scene(dev);
    // The count buffer says 1: only the empty draw runs, the rect's does not.
    const VkDrawIndirectCommand draws[] = {{0, 1, 0, 0}, {6, 1, 0, 0}};
    auto draw_args = indirect_buffer(dev, draws, sizeof draws);
    const std::uint32_t count = 1;
    auto count_buffer = indirect_buffer(dev, &count, sizeof count);
    OneShot s(q);
    scene.begin(s.cmd);
    s.cmd.draw_indirect_count(draw_args, 0, count_buffer, 0, 2);
    scene.end(s.cmd);
    s.run(q);
    EXPECT_EQ(texel(scene.pixels, 8, 4, 4), black);

    const std::uint32_t indices[] = {0, 1, 2, 3, 4, 5};
    auto index_buffer = indirect_buffer(dev, indices, sizeof indices, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
    const VkDrawIndexedIndirectCommand indexed[] = {{6, 1, 0, 0, 0}, {0, 1, 0, 0, 0}};
    auto indexed_args = indirect_buffer(dev, indexed, sizeof indexed);
    OneShot t(q);
    scene.begin(t.cmd);
    t.cmd.bind_index_buffer(index_buffer);
    t.cmd.draw_indexed_indirect_count(indexed_args, 0, count_buffer, 0, 2);
    scene.end(t.cmd);
    t.run(q);
    EXPECT_EQ(texel(scene.pixels, 8, 4, 4), green);
}

// Query

TEST_F(VulkanTest, QueryOcclusionCountsSamplesThatPass) {
    IndirectScene scene(device);
    auto queries = vkrc::QueryPool::create(device, {.query_type = VK_QUERY_TYPE_OCCLUSION, .query_count = 2});
    EXPECT_EQ(queries.query_type(), VK_QUERY_TYPE_OCCLUSION);
    EXPECT_EQ(queries.values_per_query(), 1u);
    OneShot s(queue);
    s.cmd.reset_query_pool(queries, 0, 2);
    scene.begin(s.cmd);
    s.cmd.begin_query(queries, 0);
    s.cmd.draw(6);
    s.cmd.end_query(queries, 0);
    s.cmd.begin_query(queries, 1);
    s.cmd.end_query(queries, 1);
    scene.end(s.cmd);
    s.run(queue);
    std::uint64_t results[2] = {};
    EXPECT_EQ(queries.results(0, results), VK_SUCCESS);
    EXPECT_GT(results[0], 0u);
    EXPECT_EQ(results[1], 0u);
}

TEST_F(VulkanTest, QueryPipelineStatisticsCountVerticesAndPrimitives) {
    SupportedFeatures supported(physical_device);
    if (!supported.f10.pipelineStatisticsQuery) GTEST_SKIP() << "the device lacks pipelineStatisticsQuery";
    VkPhysicalDeviceFeatures f{};
    f.pipelineStatisticsQuery = VK_TRUE;
    auto dev = device_with(physical_device, f);
    auto q = dev.default_queue();
    IndirectScene scene(dev);
    auto queries = vkrc::QueryPool::create(
        dev, {.query_type = VK_QUERY_TYPE_PIPELINE_STATISTICS,
              .query_count = 1,
              .pipeline_statistics = VK_QUERY_PIPELINE_STATISTIC_INPUT_ASSEMBLY_VERTICES_BIT |
                                     VK_QUERY_PIPELINE_STATISTIC_INPUT_ASSEMBLY_PRIMITIVES_BIT});
    ASSERT_EQ(queries.values_per_query(), 2u);
    OneShot s(q);
    s.cmd.reset_query_pool(queries, 0, 1);
    scene.begin(s.cmd);
    s.cmd.begin_query(queries, 0);
    s.cmd.draw(6);
    s.cmd.end_query(queries, 0);
    scene.end(s.cmd);
    s.run(q);
    std::uint64_t stats[2] = {};
    EXPECT_EQ(queries.results(0, stats), VK_SUCCESS);
    EXPECT_EQ(stats[0], 6u);  // vertices
    EXPECT_EQ(stats[1], 2u);  // triangles
    // Half a query's values: refused, not left half written.
    EXPECT_THROW((void)queries.results(0, std::span(stats, 1)), vkrc::UsageError);
}

TEST_F(VulkanTest, QueryTimestampsCopiedToABuffer) {
    if (physical_device.properties().limits.timestampComputeAndGraphics == VK_FALSE)
        GTEST_SKIP() << "the device lacks timestampComputeAndGraphics";
    auto queries = vkrc::QueryPool::create(device, {.query_count = 2});
    auto copy = host_buffer(device, 16, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    OneShot s(queue);
    s.cmd.reset_query_pool(queries, 0, 2);
    s.cmd.write_timestamp(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, queries, 0);
    s.cmd.write_timestamp(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, queries, 1);
    s.cmd.copy_query_results(queries, 0, 2, copy, 0, 8);
    auto to_host = vkrc::buffer_barrier(copy.vk(), copy_stage, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                        VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    s.cmd.pipeline_barrier({}, std::span(&to_host, 1), {});
    s.run(queue);
    std::uint64_t stamps[2] = {};
    EXPECT_EQ(queries.results(0, stamps), VK_SUCCESS);
    EXPECT_LE(stamps[0], stamps[1]);
    EXPECT_EQ(copy.allocation().read_value<std::uint64_t>(0), stamps[0]);
    EXPECT_EQ(copy.allocation().read_value<std::uint64_t>(8), stamps[1]);
}

TEST_F(VulkanTest, QueryPoolRejectsStatisticsWithoutFlags) {
    EXPECT_THROW(vkrc::QueryPool::create(device, {.query_type = VK_QUERY_TYPE_PIPELINE_STATISTICS, .query_count = 1}),
                 vkrc::UsageError);
}

// DebugUtils

// The command-buffer labels the layer gives a message (DebugMessage has no
// labels: a raw messenger hears them).
VKAPI_ATTR VkBool32 VKAPI_CALL hear_labels(VkDebugUtilsMessageSeverityFlagBitsEXT, VkDebugUtilsMessageTypeFlagsEXT,
                                           const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    auto& heard = *static_cast<std::vector<std::string>*>(user);
    for (std::uint32_t i = 0; i < data->cmdBufLabelCount; ++i) heard.emplace_back(data->pCmdBufLabels[i].pLabelName);
    return VK_FALSE;
}

// A label open on a command buffer reaches the validation layer: a message
// about a command recorded inside it carries the label.
TEST_F(VulkanTest, DebugUtilsLabelsReachMessagesAboutTheCommandBuffer) {
    std::vector<std::string> heard;
    VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
    info.pfnUserCallback = hear_labels;
    info.pUserData = &heard;
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    ASSERT_EQ(instance.fn().vkCreateDebugUtilsMessengerEXT(instance.vk(), &info, nullptr, &messenger), VK_SUCCESS);
    auto buffer = vkrc::Buffer::create(device, {.size = 64, .usage = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT});
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();  // never submitted
    cmd.begin();
    cmd.begin_label("outer pass");
    cmd.begin_label("inner pass");
    device.fn().vkCmdFillBuffer(cmd.vk(), buffer.vk(), 0, 4, 0);  // no TRANSFER_DST usage: reported
    cmd.end_label();
    cmd.end_label();
    cmd.end();
    instance.fn().vkDestroyDebugUtilsMessengerEXT(instance.vk(), messenger, nullptr);
    EXPECT_TRUE(log->take_expected("VUID-vkCmdFillBuffer-dstBuffer-00029", 1));
    EXPECT_NE(std::find(heard.begin(), heard.end(), "outer pass"), heard.end());
    EXPECT_NE(std::find(heard.begin(), heard.end(), "inner pass"), heard.end());
}

// Balanced labels on a submitted command buffer and on its queue.
TEST_F(VulkanTest, DebugUtilsLabelsOnCommandBuffersAndQueues) {
    ASSERT_NE(device.fn().vkCmdBeginDebugUtilsLabelEXT, nullptr);  // validation enables debug utils
    queue.begin_label("frame", {0.2f, 0.4f, 0.6f, 1.0f});
    OneShot s(queue);
    s.cmd.begin_label("pass", {1.0f, 0.0f, 0.0f, 1.0f});
    s.cmd.insert_label("marker");
    s.cmd.end_label();
    queue.insert_label("before submit");
    s.run(queue);
    queue.end_label();
}

TEST(DebugUtils, LabelsAreNoOpsWithoutTheExtension) {
    auto instance = vkrc::Instance::create({.application_name = "vkrc tests"});
    auto device = vkrc::Device::create(vkrc::PhysicalDevice::select(instance, vkrc_test::test_device_requirements()));
    EXPECT_EQ(device.fn().vkCmdBeginDebugUtilsLabelEXT, nullptr);  // dropped: the extension is off
    auto queue = device.default_queue();
    queue.begin_label("frame");
    OneShot s(queue);
    s.cmd.begin_label("pass");
    s.cmd.insert_label("marker");
    s.cmd.end_label();
    s.run(queue);
    queue.end_label();
}

}  // namespace
