// Sampler Y'CbCr conversions, and the samplers and image views made with one.
#include "support/features.hpp"
#include "support/vk_test.hpp"

#include "shaders/sample_ycbcr.comp.h"

#include <algorithm>
#include <cstring>
#include <span>

namespace {

using vkrc_test::VulkanTest;

constexpr VkFormat nv12 = VK_FORMAT_G8_B8R8_2PLANE_420_UNORM;

// The fixture's device replaced by one with samplerYcbcrConversion; skips
// where the device or its NV12 format lacks what a conversion needs.
class YcbcrTest : public VulkanTest {
protected:
    void SetUp() override {
        VulkanTest::SetUp();
        if (!vkrc_test::supported_features(physical_device).v11.samplerYcbcrConversion)
            GTEST_SKIP() << "the device lacks samplerYcbcrConversion";
        VkFormatProperties props{};
        physical_device.fn().vkGetPhysicalDeviceFormatProperties(physical_device.vk(), nv12, &props);
        const VkFormatFeatureFlags f = props.optimalTilingFeatures;
        if (!(f & VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT)) {
            GTEST_SKIP() << "VK_FORMAT_G8_B8R8_2PLANE_420_UNORM lacks VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT "
                            "(optimal tiling)";
        }
        if (!(f & (VK_FORMAT_FEATURE_MIDPOINT_CHROMA_SAMPLES_BIT | VK_FORMAT_FEATURE_COSITED_CHROMA_SAMPLES_BIT))) {
            GTEST_SKIP() << "VK_FORMAT_G8_B8R8_2PLANE_420_UNORM lacks VK_FORMAT_FEATURE_MIDPOINT_CHROMA_SAMPLES_BIT "
                            "and VK_FORMAT_FEATURE_COSITED_CHROMA_SAMPLES_BIT";
        }
        location = (f & VK_FORMAT_FEATURE_MIDPOINT_CHROMA_SAMPLES_BIT) ? VK_CHROMA_LOCATION_MIDPOINT
                                                                       : VK_CHROMA_LOCATION_COSITED_EVEN;
        vkrc::DeviceCreateInfo info;
        info.vulkan11_features.samplerYcbcrConversion = VK_TRUE;
        device = vkrc::Device::create(physical_device, info);
        queue = device.default_queue();
    }
    vkrc::SamplerYcbcrConversion nv12_conversion(const vkrc::Device& on) const {
        return vkrc::SamplerYcbcrConversion::create(
            on, {.format = nv12, .x_chroma_offset = location, .y_chroma_offset = location});
    }
    VkChromaLocation location = VK_CHROMA_LOCATION_MIDPOINT;
};

TEST_F(YcbcrTest, YcbcrConversionWithSamplerAndImageView) {
    auto conversion = nv12_conversion(device);
    EXPECT_EQ(conversion.format(), nv12);
    auto sampler = vkrc_test::ycbcr_sampler(device, conversion);
    auto image =
        vkrc::Image::create(device, {.format = nv12, .extent = {4, 4, 1}, .usage = VK_IMAGE_USAGE_SAMPLED_BIT});
    auto view = vkrc::ImageView::create(image, {.ycbcr_conversion = conversion});
    EXPECT_NE(sampler.vk(), VK_NULL_HANDLE);
    EXPECT_NE(view.vk(), VK_NULL_HANDLE);
    EXPECT_EQ(conversion.use_count(), 3u) << "the sampler and the view keep the conversion alive";
    conversion.reset();  // the view and sampler still hold it: no validation error at their destruction
}

// A conversion made with the raw API samples like vkrc's own; owned, vkrc
// destroys it, borrowed, its maker does (the layer reports a leak or a double destroy).
TEST_F(YcbcrTest, YcbcrAdoptedConversion) {
    for (const auto ownership : {vkrc::Ownership::owned, vkrc::Ownership::borrowed}) {
        VkSamplerYcbcrConversionCreateInfo ci{VK_STRUCTURE_TYPE_SAMPLER_YCBCR_CONVERSION_CREATE_INFO};
        ci.format = nv12;
        ci.ycbcrModel = VK_SAMPLER_YCBCR_MODEL_CONVERSION_YCBCR_709;
        ci.ycbcrRange = VK_SAMPLER_YCBCR_RANGE_ITU_FULL;
        ci.xChromaOffset = ci.yChromaOffset = location;
        ci.chromaFilter = VK_FILTER_NEAREST;
        VkSamplerYcbcrConversion raw = VK_NULL_HANDLE;
        ASSERT_EQ(device.fn().vkCreateSamplerYcbcrConversion(device.vk(), &ci, nullptr, &raw), VK_SUCCESS);
        {
            auto conversion = vkrc::SamplerYcbcrConversion::adopt(device, raw, nv12, ownership);
            EXPECT_EQ(conversion.format(), nv12);
            auto image =
                vkrc::Image::create(device, {.format = nv12, .extent = {4, 4, 1}, .usage = VK_IMAGE_USAGE_SAMPLED_BIT});
            auto view = vkrc::ImageView::create(image, {.ycbcr_conversion = conversion});
            EXPECT_NE(view.vk(), VK_NULL_HANDLE);
        }
        device.wait_idle();  // runs a (wrongly) deferred destruction before the raw one
        if (ownership == vkrc::Ownership::borrowed) {
            device.fn().vkDestroySamplerYcbcrConversion(device.vk(), raw, nullptr);
        }
    }
    EXPECT_THROW(vkrc::SamplerYcbcrConversion::adopt(device, VK_NULL_HANDLE, nv12, vkrc::Ownership::owned),
                 vkrc::UsageError);
}

// Shaders reach a Y'CbCr sampler only as an immutable sampler of a set layout,
// which keeps it (and so the conversion) alive. A 4x4 NV12 image of Y' 16,
// Cb 128, Cr 240 (BT.709, narrow range: Y 0, Cb 0, Cr 0.5) samples as
// R = 1.5748 * 0.5 (201 of 255), G and B 0 (clamped), through a layout whose
// sampler's handle is gone.
TEST_F(YcbcrTest, YcbcrSamplerImmutableInASetLayout) {
    auto conversion = nv12_conversion(device);
    auto set_layout = vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{.binding = 0,
                               .descriptor_type = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                               .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT,
                               .immutable_samplers = {vkrc_test::ycbcr_sampler(device, conversion)}},
                              {.binding = 1,
                               .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                               .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT}}});
    EXPECT_EQ(conversion.use_count(), 2u) << "held by the layout's sampler";
    // A multi-planar format may take several descriptors of the pool (up to one per plane).
    auto pool = vkrc::DescriptorPool::create(device, {.max_sets = 1,
                                                      .pool_sizes = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 3},
                                                                     {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
    auto set = pool.allocate(set_layout);
    auto image = vkrc::Image::create(
        device,
        {.format = nv12, .extent = {4, 4, 1}, .usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT});
    auto view = vkrc::ImageView::create(image, {.ycbcr_conversion = conversion});
    auto out = vkrc::Buffer::create(
        device, {.size = 64, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, .memory = {vkrc::MemoryUsage::readback}});
    set.write_image(0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, out);
    auto staging = vkrc::Buffer::create(
        device, {.size = 24, .usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT, .memory = {vkrc::MemoryUsage::upload}});
    std::uint8_t planes[24];
    std::fill(planes, planes + 16, std::uint8_t{16});                       // Y', 4x4
    for (int i = 16; i < 24; i += 2) planes[i] = 128, planes[i + 1] = 240;  // Cb Cr, 2x2
    staging.allocation().write(0, planes, sizeof planes);
    auto layout = vkrc::PipelineLayout::create(
        device, {.set_layouts = {set_layout}, .push_constant_ranges = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, 8}}});
    auto pipeline =
        vkrc::ComputePipeline::create(layout, vkrc::ShaderModule::create(device, vkrc_shaders::sample_ycbcr_comp));
    auto commands = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = commands.allocate();
    cmd.begin();
    auto to_copy = vkrc::image_barrier(image.vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                       VK_PIPELINE_STAGE_2_NONE, 0, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                                       VK_ACCESS_2_TRANSFER_WRITE_BIT);
    cmd.pipeline_barrier({}, {}, std::span(&to_copy, 1));
    VkBufferImageCopy regions[2]{};
    regions[0].imageSubresource = {VK_IMAGE_ASPECT_PLANE_0_BIT, 0, 0, 1};
    regions[0].imageExtent = {4, 4, 1};
    regions[1].bufferOffset = 16;
    regions[1].imageSubresource = {VK_IMAGE_ASPECT_PLANE_1_BIT, 0, 0, 1};
    regions[1].imageExtent = {2, 2, 1};
    cmd.copy_buffer_to_image(staging, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, regions);
    auto to_sample =
        vkrc::image_barrier(image.vk(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                            VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                            VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
    cmd.pipeline_barrier({}, {}, std::span(&to_sample, 1));
    cmd.bind_pipeline(pipeline);
    cmd.bind_descriptor_set(pipeline, 0, set);
    const std::uint32_t params[2] = {4, 4};
    cmd.push_constants(layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(params), params);
    cmd.dispatch(1, 1);
    auto to_host = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                        VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    cmd.end();
    auto fence = vkrc::Fence::create(device);
    vkrc::submit(queue, {.command_buffers = std::span(&cmd, 1)}, fence);
    ASSERT_EQ(fence.wait(), VK_SUCCESS);
    for (VkDeviceSize texel = 0; texel < 16; ++texel) {
        vkrc_test::Rgba rgba;
        const auto packed = out.allocation().read_value<std::uint32_t>(texel * 4);
        std::memcpy(rgba.data(), &packed, 4);
        EXPECT_TRUE(vkrc_test::within_one(rgba, {201, 0, 0, 255})) << "texel " << texel;
    }
}

TEST_F(YcbcrTest, YcbcrMisuseIsAUsageError) {
    EXPECT_THROW(vkrc::SamplerYcbcrConversion::create(device, {}), vkrc::UsageError) << "format undefined";
    vkrc::DeviceCreateInfo info;
    info.vulkan11_features.samplerYcbcrConversion = VK_TRUE;
    auto other = vkrc::Device::create(physical_device, info);
    EXPECT_THROW(vkrc::Sampler::create(device, {.ycbcr_conversion = nv12_conversion(other)}), vkrc::UsageError)
        << "a conversion of another device";
    auto sampler = vkrc_test::ycbcr_sampler(device, nv12_conversion(device));
    EXPECT_THROW(vkrc::DescriptorSetLayout::create(
                     device, {.bindings = {{.binding = 0,
                                            .descriptor_type = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                                            .descriptor_count = 2,
                                            .immutable_samplers = {sampler}}}}),
                 vkrc::UsageError)
        << "one immutable sampler for two descriptors";
    EXPECT_THROW(
        vkrc::DescriptorSetLayout::create(device, {.bindings = {{.binding = 0,
                                                                 .descriptor_type = VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE,
                                                                 .immutable_samplers = {sampler}}}}),
        vkrc::UsageError)
        << "immutable samplers on a sampled-image binding";
}

}  // namespace
