// Mesh and task shading (VK_EXT_mesh_shader): GraphicsPipelineBuilder with
// mesh and task stages, draw_mesh_tasks and its indirect forms, each image
// read back and compared pixel by pixel with the cells it should cover; the
// builder's refusals; and the features chosen through DeviceRequirements.
#include "support/features.hpp"
#include "support/vk_test.hpp"

#include "shaders/green.frag.h"
#include "shaders/mesh_cells.mesh.h"
#include "shaders/rect.vert.h"
#include "shaders/staircase.mesh.h"
#include "shaders/staircase.task.h"

#include <array>
#include <functional>
#include <span>
#include <string>
#include <vector>

namespace {

using vkrc_test::Rgba;
using vkrc_test::VulkanTest;
using OneShot = vkrc_test::OneShotCommands;

// The shaders draw cells of a 4x4 grid, each 4x4 pixels of a 16x16 target.
constexpr std::uint32_t grid = 4, cell = 4, size = grid * cell;
constexpr VkFormat rgba8 = VK_FORMAT_R8G8B8A8_UNORM;
constexpr Rgba green{0, 255, 0, 255}, black{0, 0, 0, 255};

// Which cells a draw covers, by cell: covered(x, y).
using Coverage = std::function<bool(std::uint32_t, std::uint32_t)>;

// What the mesh tests need that physical lacks; empty when it has it all.
std::string missing_mesh_features(const vkrc::PhysicalDevice& physical) {
    if (!physical.supports_extension(VK_EXT_MESH_SHADER_EXTENSION_NAME)) return "VK_EXT_mesh_shader";
    const auto& f = physical.features();
    return vkrc_test::missing_features({{"taskShader", f.mesh_shader.taskShader},
                                        {"meshShader", f.mesh_shader.meshShader},
                                        {"drawIndirectCount", f.vulkan12.drawIndirectCount}});
}

// The fixture's device replaced by one with task and mesh shaders (and
// drawIndirectCount, multiDrawIndirect where offered); skips where the device lacks them.
class MeshShaderTest : public VulkanTest {
protected:
    void SetUp() override {
        VulkanTest::SetUp();
        if (auto missing = missing_mesh_features(physical_device); !missing.empty())
            GTEST_SKIP() << "the device lacks " << missing;
        vkrc::DeviceCreateInfo info;
        info.mesh_shader_features.taskShader = VK_TRUE;
        info.mesh_shader_features.meshShader = VK_TRUE;
        info.vulkan12_features.drawIndirectCount = VK_TRUE;
        info.enabled_features.multiDrawIndirect = physical_device.features().core.multiDrawIndirect;
        device = vkrc::Device::create(physical_device, info);
        queue = device.default_queue();
    }

    vkrc::ShaderModule module(std::span<const std::uint32_t> code) const {
        return vkrc::ShaderModule::create(device, code);
    }
    vkrc::GraphicsPipelineBuilder builder() const {
        vkrc::GraphicsPipelineBuilder b(vkrc::PipelineLayout::create(device));
        b.shader(VK_SHADER_STAGE_FRAGMENT_BIT, module(vkrc_shaders::green_frag))
            .cull_mode(VK_CULL_MODE_NONE)
            .rendering(std::array{rgba8});
        return b;
    }
    // mesh_cells.mesh alone: workgroup (x, y) draws cell (x, y).
    vkrc::GraphicsPipeline cells_pipeline() const {
        return builder().shader(VK_SHADER_STAGE_MESH_BIT_EXT, module(vkrc_shaders::mesh_cells_mesh)).build();
    }
    // staircase.task and .mesh: task workgroup t draws the first t + 1 cells of row t.
    vkrc::GraphicsPipeline staircase_pipeline() const {
        return builder()
            .shader(VK_SHADER_STAGE_TASK_BIT_EXT, module(vkrc_shaders::staircase_task))
            .shader(VK_SHADER_STAGE_MESH_BIT_EXT, module(vkrc_shaders::staircase_mesh))
            .build();
    }

    // Clears a 16x16 target to black, binds pipeline, records draw and
    // returns the pixels read back.
    std::vector<Rgba> render(const vkrc::GraphicsPipeline& pipeline,
                             const std::function<void(const vkrc::CommandBuffer&)>& draw) const {
        auto image = vkrc::Image::create(
            device, {.format = rgba8,
                     .extent = {size, size, 1},
                     .usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
        auto view = vkrc::ImageView::create(image);
        auto pixels = vkrc::Buffer::create(device, {.size = size * size * 4,
                                                    .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                                    .memory = {.usage = vkrc::MemoryUsage::readback}});
        OneShot s(queue);
        const auto to_attachment = vkrc::image_barrier(
            image.vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_NONE,
            0, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
        s.cmd.pipeline_barrier({}, {}, std::span(&to_attachment, 1));
        vkrc::RenderingAttachment color{.image_view = view.vk()};
        color.clear_value.color = {{0.0f, 0.0f, 0.0f, 1.0f}};
        s.cmd.begin_rendering({.render_area = {{0, 0}, {size, size}}, .color_attachments = std::span(&color, 1)});
        s.cmd.set_viewport_and_scissor({size, size});
        s.cmd.bind_pipeline(pipeline);
        draw(s.cmd);
        s.cmd.end_rendering();
        const auto to_copy = vkrc::image_barrier(
            image.vk(), VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
            VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
            VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
        s.cmd.pipeline_barrier({}, {}, std::span(&to_copy, 1));
        vkrc_test::record_readback(s.cmd, image.vk(), pixels.vk(), size, size);
        s.run(queue);
        std::vector<Rgba> out(size * size);
        pixels.allocation().read(0, out.data(), out.size());
        return out;
    }

    // A buffer holding bytes of data with usage (an indirect or count buffer).
    vkrc::Buffer buffer_of(const void* data, std::size_t bytes) const {
        auto b = vkrc::Buffer::create(device, {.size = bytes,
                                               .usage = VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT,
                                               .memory = {.usage = vkrc::MemoryUsage::upload}});
        b.allocation().write(0, std::span(static_cast<const std::byte*>(data), bytes));
        return b;
    }
};

// Every pixel is green where its cell is covered and black elsewhere.
::testing::AssertionResult matches(const std::vector<Rgba>& pixels, const Coverage& covered) {
    for (std::uint32_t y = 0; y < size; ++y) {
        for (std::uint32_t x = 0; x < size; ++x) {
            const Rgba want = covered(x / cell, y / cell) ? green : black;
            const Rgba got = pixels[y * size + x];
            if (got != want) {
                return ::testing::AssertionFailure()
                       << "pixel " << x << "," << y << " is " << int(got[0]) << "," << int(got[1]) << "," << int(got[2])
                       << "," << int(got[3]) << ", want " << (want == green ? "green" : "black");
            }
        }
    }
    return ::testing::AssertionSuccess();
}

// The cells x < width, y < height.
Coverage block(std::uint32_t width, std::uint32_t height) {
    return [=](std::uint32_t x, std::uint32_t y) { return x < width && y < height; };
}
const Coverage nothing = [](std::uint32_t, std::uint32_t) { return false; };

TEST_F(MeshShaderTest, MeshPipelineDrawsTheCellsOfItsWorkgroups) {
    const auto pipeline = cells_pipeline();
    EXPECT_TRUE(matches(render(pipeline, [](const auto& cmd) { cmd.draw_mesh_tasks(3, 2, 1); }), block(3, 2)));
    EXPECT_TRUE(matches(render(pipeline, [](const auto& cmd) { cmd.draw_mesh_tasks(grid, grid); }), block(grid, grid)));
}

TEST_F(MeshShaderTest, TaskShaderLaunchesTheMeshWorkgroups) {
    const auto pipeline = staircase_pipeline();
    const auto pixels = render(pipeline, [](const auto& cmd) { cmd.draw_mesh_tasks(3); });
    EXPECT_TRUE(matches(pixels, [](std::uint32_t x, std::uint32_t y) { return y < 3 && x <= y; }));
}

TEST_F(MeshShaderTest, IndirectDrawReadsTheGroupCountsFromABuffer) {
    const auto pipeline = cells_pipeline();
    // The command at offset 12, past one that would cover the whole grid.
    const VkDrawMeshTasksIndirectCommandEXT commands[] = {{grid, grid, 1}, {2, 4, 1}};
    const auto args = buffer_of(commands, sizeof commands);
    const auto pixels = render(pipeline, [&](const auto& cmd) {
        cmd.draw_mesh_tasks_indirect(args, sizeof(VkDrawMeshTasksIndirectCommandEXT), 1);
    });
    EXPECT_TRUE(matches(pixels, block(2, 4)));
    // Through the task shader: one task workgroup per row, four rows.
    const VkDrawMeshTasksIndirectCommandEXT rows{grid, 1, 1};
    const auto row_args = buffer_of(&rows, sizeof rows);
    EXPECT_TRUE(
        matches(render(staircase_pipeline(), [&](const auto& cmd) { cmd.draw_mesh_tasks_indirect(row_args, 0, 1); }),
                [](std::uint32_t x, std::uint32_t y) { return x <= y; }));
}

TEST_F(MeshShaderTest, IndirectCountDrawsUpToTheCountInTheBuffer) {
    const auto pipeline = cells_pipeline();
    const VkDrawMeshTasksIndirectCommandEXT commands[] = {{1, 3, 1}, {grid, 1, 1}};
    const auto args = buffer_of(commands, sizeof commands);
    // Counts 0, 1, 5 and 2 at offsets 0, 4, 8 and 12.
    const std::uint32_t counts[] = {0, 1, 5, 2};
    const auto count_buffer = buffer_of(counts, sizeof counts);
    const auto draw_up_to = [&](VkDeviceSize count_offset, std::uint32_t max_draw_count) {
        return render(pipeline, [&](const auto& cmd) {
            cmd.draw_mesh_tasks_indirect_count(args, 0, count_buffer, count_offset, max_draw_count);
        });
    };
    EXPECT_TRUE(matches(draw_up_to(0, 1), nothing)) << "count 0 draws nothing";
    EXPECT_TRUE(matches(draw_up_to(4, 1), block(1, 3))) << "count 1";
    EXPECT_TRUE(matches(draw_up_to(8, 1), block(1, 3))) << "count 5 clamped to max_draw_count 1";
    if (!physical_device.features().core.multiDrawIndirect) return;  // more than one draw needs it
    const auto both = [](std::uint32_t x, std::uint32_t y) { return (x < 1 && y < 3) || y < 1; };
    EXPECT_TRUE(matches(draw_up_to(12, 2), both)) << "count 2: both commands";
    EXPECT_TRUE(matches(draw_up_to(4, 2), block(1, 3))) << "count 1 of at most 2";
}

// Builds b and returns the UsageError's message ("" when it builds).
std::string build_refusal(const vkrc::GraphicsPipelineBuilder& b) {
    try {
        b.build();
    } catch (const vkrc::UsageError& e) {
        return e.what();
    }
    return "";
}

TEST_F(MeshShaderTest, BuilderRefusesVertexStagesOrInputBesideAMeshStage) {
    const auto mesh = module(vkrc_shaders::mesh_cells_mesh);
    auto with_vertex = builder();
    with_vertex.shader(VK_SHADER_STAGE_MESH_BIT_EXT, mesh)
        .shader(VK_SHADER_STAGE_VERTEX_BIT, module(vkrc_shaders::rect_vert));
    EXPECT_EQ(build_refusal(with_vertex),
              "vkrc::GraphicsPipelineBuilder::build: a mesh shader with vertex, tessellation or geometry shaders "
              "(stage flags 0x1): a pipeline has one or the other");

    auto with_binding = builder();
    with_binding.shader(VK_SHADER_STAGE_MESH_BIT_EXT, mesh).vertex_binding(0, 16);
    EXPECT_EQ(build_refusal(with_binding),
              "vkrc::GraphicsPipelineBuilder::build: vertex bindings or attributes (1 and 0) with a mesh shader, "
              "which has no vertex input");
    auto with_attribute = builder();
    with_attribute.shader(VK_SHADER_STAGE_MESH_BIT_EXT, mesh).vertex_attribute(0, 0, VK_FORMAT_R32G32_SFLOAT, 0);
    EXPECT_EQ(build_refusal(with_attribute),
              "vkrc::GraphicsPipelineBuilder::build: vertex bindings or attributes (0 and 1) with a mesh shader, "
              "which has no vertex input");

    auto task_alone = builder();
    task_alone.shader(VK_SHADER_STAGE_TASK_BIT_EXT, module(vkrc_shaders::staircase_task));
    EXPECT_EQ(build_refusal(task_alone), "vkrc::GraphicsPipelineBuilder::build: a task shader without a mesh shader");
}

// The fixture's own device, made without the features, refuses the stages
// before Vulkan sees them (any module will do: nothing is created).
TEST_F(VulkanTest, MeshAndTaskStagesNeedTheDeviceFeatures) {
    const auto module = vkrc::ShaderModule::create(device, vkrc_shaders::rect_vert);
    vkrc::GraphicsPipelineBuilder b(vkrc::PipelineLayout::create(device));
    const auto refusal = [&](VkShaderStageFlagBits stage) -> std::string {
        try {
            b.shader(stage, module);
        } catch (const vkrc::UsageError& e) {
            return e.what();
        }
        return "";
    };
    EXPECT_EQ(refusal(VK_SHADER_STAGE_MESH_BIT_EXT),
              "vkrc::GraphicsPipelineBuilder::shader: a mesh shader on a device created without the meshShader "
              "feature (DeviceCreateInfo::mesh_shader_features)");
    EXPECT_EQ(refusal(VK_SHADER_STAGE_TASK_BIT_EXT),
              "vkrc::GraphicsPipelineBuilder::shader: a task shader on a device created without the taskShader "
              "feature (DeviceCreateInfo::mesh_shader_features)");
}

// DeviceRequirements takes the mesh features like the core ones: met where
// the device has them, named with their extension where it lacks one.
TEST_F(VulkanTest, DeviceRequirementsNameMissingMeshShaderFeatures) {
    const auto& have = physical_device.features().mesh_shader;
    vkrc::DeviceRequirements req = vkrc_test::test_device_requirements();
    req.required_features.mesh_shader.meshShader = have.meshShader;
    req.required_features.mesh_shader.taskShader = have.taskShader;
    EXPECT_TRUE(physical_device.unmet_requirements(req).empty());
    const std::pair<VkBool32 VkPhysicalDeviceMeshShaderFeaturesEXT::*, const char*> candidates[] = {
        {&VkPhysicalDeviceMeshShaderFeaturesEXT::meshShader, "meshShader"},
        {&VkPhysicalDeviceMeshShaderFeaturesEXT::taskShader, "taskShader"},
        {&VkPhysicalDeviceMeshShaderFeaturesEXT::multiviewMeshShader, "multiviewMeshShader"},
        {&VkPhysicalDeviceMeshShaderFeaturesEXT::primitiveFragmentShadingRateMeshShader,
         "primitiveFragmentShadingRateMeshShader"},
        {&VkPhysicalDeviceMeshShaderFeaturesEXT::meshShaderQueries, "meshShaderQueries"}};
    for (const auto& [member, name] : candidates) {
        if (have.*member) continue;
        req.required_features.mesh_shader.*member = VK_TRUE;
        const auto reasons = physical_device.unmet_requirements(req);
        ASSERT_EQ(reasons.size(), 1u);
        EXPECT_EQ(std::string(reasons[0].c_str()), std::string("lacks feature ") + name + " (VK_EXT_mesh_shader)");
        return;
    }
    GTEST_SKIP() << "the device has every mesh shader feature";
}

}  // namespace
