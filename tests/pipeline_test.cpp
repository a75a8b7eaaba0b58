#include "support/vk_test.hpp"

#include "shaders/fill_pattern.comp.h"
#include "shaders/push_color.frag.h"
#include "shaders/rect.vert.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

using vkrc_test::VulkanTest;

struct RectPush {
    float color[4];
    float bounds[4];
    float depth;
};

vkrc::PipelineLayout rect_layout(const vkrc::Device& device) {
    return vkrc::PipelineLayout::create(
        device,
        {.push_constant_ranges = {{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(RectPush)}}});
}

TEST_F(VulkanTest, GraphicsPipelineForARenderPass) {
    VkAttachmentDescription color{0,
                                  VK_FORMAT_R8G8B8A8_UNORM,
                                  VK_SAMPLE_COUNT_1_BIT,
                                  VK_ATTACHMENT_LOAD_OP_CLEAR,
                                  VK_ATTACHMENT_STORE_OP_STORE,
                                  VK_ATTACHMENT_LOAD_OP_DONT_CARE,
                                  VK_ATTACHMENT_STORE_OP_DONT_CARE,
                                  VK_IMAGE_LAYOUT_UNDEFINED,
                                  VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
    auto render_pass = vkrc::RenderPass::create(
        device, {.attachments = {color},
                 .subpasses = {{.color_attachments = {{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL}}}}});
    EXPECT_EQ(render_pass.color_attachment_count(0), 1u);
    EXPECT_THROW((void)render_pass.color_attachment_count(1), vkrc::UsageError);
    auto pipeline =
        vkrc::GraphicsPipelineBuilder(rect_layout(device))
            .shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::rect_vert))
            .shader(VK_SHADER_STAGE_FRAGMENT_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::push_color_frag))
            .render_pass(render_pass)
            .build();
    EXPECT_EQ(pipeline.bind_point(), VK_PIPELINE_BIND_POINT_GRAPHICS);
    EXPECT_TRUE(pipeline.layout());
}

TEST_F(VulkanTest, GraphicsPipelineBuilderNamesMissingParts) {
    try {
        vkrc::GraphicsPipelineBuilder(rect_layout(device)).build();
        FAIL() << "no UsageError";
    } catch (const vkrc::UsageError& e) {
        EXPECT_STREQ(e.what(), "vkrc::GraphicsPipelineBuilder::build: no shader stages");
    }
}

TEST_F(VulkanTest, PipelineCacheRoundTripsThroughAFile) {
    auto dir = std::filesystem::temp_directory_path() /
               ("vkrc-cache-" + std::to_string(reinterpret_cast<std::uintptr_t>(this)) + "-" +
                std::to_string(VKRC_IS_MULTI_THREAD));
    std::filesystem::create_directories(dir);
    auto file = dir / "pipelines.bin";
    auto module = vkrc::ShaderModule::create(device, vkrc_shaders::fill_pattern_comp);
    auto set_layout = vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{.binding = 0, .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}}});
    auto layout = vkrc::PipelineLayout::create(
        device, {.set_layouts = {set_layout}, .push_constant_ranges = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, 8}}});
    {
        auto cache = vkrc::PipelineCache::create(device);
        EXPECT_FALSE(cache.loaded_from_file());
        auto pipeline = vkrc::ComputePipeline::create(layout, module, "main", cache);
        EXPECT_EQ(pipeline.bind_point(), VK_PIPELINE_BIND_POINT_COMPUTE);
        cache.save(file.c_str());
    }
    ASSERT_TRUE(std::filesystem::exists(file));
    auto loaded = vkrc::PipelineCache::load(device, file.c_str());
    EXPECT_TRUE(loaded.loaded_from_file());
    EXPECT_FALSE(loaded.data().empty());

    // Corrupt: a valid-looking size of garbage.
    auto corrupt = dir / "corrupt.bin";
    {
        std::ofstream out(corrupt, std::ios::binary);
        std::string junk(200, '\x5a');
        out.write(junk.data(), static_cast<std::streamsize>(junk.size()));
    }
    ::testing::internal::CaptureStderr();
    auto from_corrupt = vkrc::PipelineCache::load(device, corrupt.c_str());
    std::string warning = ::testing::internal::GetCapturedStderr();
    EXPECT_FALSE(from_corrupt.loaded_from_file());
    EXPECT_NE(warning.find("vkrc warning: PipelineCache::load"), std::string::npos) << warning;

    // Foreign: this driver's header with another device's UUID.
    auto bytes = loaded.data();
    VkPipelineCacheHeaderVersionOne header;
    std::memcpy(&header, bytes.data(), sizeof header);
    header.pipelineCacheUUID[0] ^= 0xff;
    std::memcpy(bytes.data(), &header, sizeof header);
    auto foreign = dir / "foreign.bin";
    {
        std::ofstream out(foreign, std::ios::binary);
        out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    }
    ::testing::internal::CaptureStderr();
    auto from_foreign = vkrc::PipelineCache::load(device, foreign.c_str());
    warning = ::testing::internal::GetCapturedStderr();
    EXPECT_FALSE(from_foreign.loaded_from_file());
    EXPECT_NE(warning.find("another driver or device"), std::string::npos) << warning;

    ::testing::internal::CaptureStderr();
    auto from_missing = vkrc::PipelineCache::load(device, (dir / "missing.bin").c_str());
    ::testing::internal::GetCapturedStderr();
    EXPECT_FALSE(from_missing.loaded_from_file());
    // An ignored file still leaves a working (empty) cache.
    auto rebuilt = vkrc::ComputePipeline::create(layout, module, "main", from_corrupt);
    EXPECT_NE(rebuilt.vk(), VK_NULL_HANDLE);
    EXPECT_FALSE(from_corrupt.data().empty());
    std::filesystem::remove_all(dir);
}

}  // namespace
