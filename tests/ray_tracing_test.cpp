// Ray tracing pipelines and shader binding tables: a known scene of
// triangles and procedural spheres traced with trace_rays and
// trace_rays_indirect, every pixel checked against the value computed here
// (closest hit, any hit, intersection, miss and callable shaders, per-record
// data, a specialization constant, shadow rays at recursion depth 2); the
// table, pipeline and structures dropped while gated work traces them; and
// a seeded fuzz of those drops over many rounds; the refusals of bad
// pipelines, tables and box geometry. No ray query: the
// NVIDIA H100 runs ray tracing pipelines without it.
#include "support/features.hpp"
#include "support/vk_test.hpp"
#include "support/wrapped_allocator.hpp"

#include "shaders/rt_scene.rahit.h"
#include "shaders/rt_scene.rcall.h"
#include "shaders/rt_scene.rchit.h"
#include "shaders/rt_scene.rgen.h"
#include "shaders/rt_scene.rmiss.h"
#include "shaders/rt_shadow.rmiss.h"
#include "shaders/rt_sphere.rint.h"

#include <array>
#include <cstdio>
#include <cstring>
#include <functional>
#include <random>
#include <span>
#include <string>
#include <vector>

namespace {

using vkrc_test::usage_error_of;
using vkrc_test::VulkanTest;
using OneShot = vkrc_test::OneShotCommands;

// The launch is 16x16; rt_scene.rgen writes results[y * 16 + x].
constexpr std::uint32_t side = 16;
constexpr std::uint32_t miss_value = 0x0FFFFFF0u;  // the miss record's data
constexpr std::uint32_t callable_bits = 0x2u;      // the callable record's data
constexpr std::uint32_t untouched = 0xDDDDDDDDu;   // what results hold before a trace
constexpr VkBufferUsageFlags input_usage =
    VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT | VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;

// The hit records' tags, selected by the instances' sbt_offset 0, 1, 2.
using Tags = std::array<std::uint32_t, 3>;
constexpr Tags default_tags{1, 2, 3};

// Spheres (centre, radius) in the procedural hit record, and their boxes.
constexpr std::array<std::array<float, 4>, 2> spheres{{{12, 4, 1, 2.5f}, {12, 12, 0, 2.5f}}};

template <class T>
vkrc::Buffer input_buffer(const vkrc::Device& device, std::span<const T> values, VkBufferUsageFlags usage) {
    auto buffer = vkrc::Buffer::create(
        device, {.size = values.size_bytes(), .usage = usage, .memory = {.usage = vkrc::MemoryUsage::upload}});
    buffer.allocation().write(0, values.data(), values.size());
    return buffer;
}

VkTransformMatrixKHR placed(float x, float y, float z, float scale = 1.0f) {
    return {{{scale, 0, 0, x}, {0, scale, 0, y}, {0, 0, scale, z}}};
}

// What rt_scene.rchit reports for a hit.
constexpr std::uint32_t hit_value(std::uint32_t tag, std::uint32_t custom, std::uint32_t geometry,
                                  std::uint32_t primitive, bool shadowed) {
    return tag << 28 | custom << 20 | geometry << 16 | primitive << 8 | (shadowed ? 1u : 0u);
}

// The scene as the instances below place it, seen along -z from pixel
// centres: quads (custom 5 at y 0, custom 7 at y 8, both moved 0.25 in x
// so no pixel centre lies on an edge) of geometry 0 [0,4]x[0,4] and
// geometry 1 [4,8]x[0,4], primitive 0 below each quad's diagonal; the any-hit
// shader drops primitive 1 of geometry 1. Spheres (custom 9) are primitives
// 0 and 1 of one box geometry. An occluder over [0.25,16.25]x[2,10] at z 5,
// seen only by the shadow rays (mask 0x02), shadows what lies under it.
std::uint32_t expected_value(std::uint32_t x, std::uint32_t y, const Tags& tags = default_tags,
                             std::uint32_t salt = 0) {
    const float cx = float(x) + 0.5f, cy = float(y) + 0.5f;
    const bool shadowed = cy > 2 && cy < 10;
    std::uint32_t value = miss_value;
    const struct {
        std::uint32_t custom;
        float y;
        std::uint32_t tag;
    } quads[] = {{5, 0, tags[0]}, {7, 8, tags[1]}};
    for (const auto& q : quads) {
        const float lx = cx - 0.25f, ly = cy - q.y;
        if (lx <= 0 || lx >= 8 || ly <= 0 || ly >= 4) continue;
        const std::uint32_t geometry = lx < 4 ? 0 : 1;
        const std::uint32_t primitive = ly < lx - 4.0f * float(geometry) ? 0 : 1;
        if (geometry == 1 && primitive == 1) continue;  // ignored by the any-hit shader
        value = hit_value(q.tag, q.custom, geometry, primitive, shadowed);
    }
    for (std::uint32_t i = 0; i < spheres.size(); ++i) {
        const float dx = cx - spheres[i][0], dy = cy - spheres[i][1];
        if (dx * dx + dy * dy < spheres[i][3] * spheres[i][3]) value = hit_value(tags[2], 9, 0, i, shadowed);
    }
    return (value | callable_bits) ^ salt;
}

// Compares results with expected(x, y) for x < columns (untouched beyond)
// and names the first pixels that differ.
template <class Expected>
void expect_results(const std::vector<std::uint32_t>& results, Expected expected, std::uint32_t columns = side) {
    int wrong = 0;
    for (std::uint32_t y = 0; y < side; ++y) {
        for (std::uint32_t x = 0; x < side; ++x) {
            const std::uint32_t want = x < columns ? expected(x, y) : untouched, got = results[y * side + x];
            if (got != want && ++wrong <= 5) {
                ADD_FAILURE() << "pixel (" << x << ", " << y << "): got 0x" << std::hex << got << ", expected 0x"
                              << want;
            }
        }
    }
    EXPECT_EQ(wrong, 0) << "pixels wrong";
}

// The stages of the scene's pipeline, in this order, and its groups.
enum Stage : std::uint32_t { raygen, scene_miss, shadow_miss, closest_hit, any_hit, intersection, callable };
enum Group : std::uint32_t { raygen_group, miss_group, shadow_group, triangles_group, spheres_group, callable_group };

// The procedural hit record's data, as rt_sphere.rint reads it (std430).
struct SphereRecord {
    std::uint32_t tag;
    std::uint32_t pad[3];
    std::array<std::array<float, 4>, 2> spheres;
};

// The geometry, the structures over it, and the records' data, each kept by
// a handle a test may drop.
struct Scene {
    vkrc::AccelerationStructure quads, boxes, top_level;
};

// What the ray tracing tests need that physical lacks; empty when it has it all.
std::string missing_ray_tracing_features(const vkrc::PhysicalDevice& physical) {
    if (!physical.supports_extension(VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME)) return "VK_KHR_ray_tracing_pipeline";
    const auto& f = physical.features();
    return vkrc_test::missing_features(
        {{"rayTracingPipeline", f.ray_tracing_pipeline.rayTracingPipeline},
         {"rayTracingPipelineTraceRaysIndirect", f.ray_tracing_pipeline.rayTracingPipelineTraceRaysIndirect},
         {"accelerationStructure", f.acceleration_structure.accelerationStructure},
         {"bufferDeviceAddress", f.vulkan12.bufferDeviceAddress}});
}

class RayTracingTest : public VulkanTest {
protected:
    void SetUp() override {
        VulkanTest::SetUp();
        if (HasFatalFailure() || IsSkipped()) return;
        if (auto missing = missing_ray_tracing_features(physical_device); !missing.empty())
            GTEST_SKIP() << "the device lacks " << missing;
        vkrc::DeviceCreateInfo info;
        info.ray_tracing_pipeline_features.rayTracingPipeline = VK_TRUE;  // enables the extensions
        info.ray_tracing_pipeline_features.rayTracingPipelineTraceRaysIndirect = VK_TRUE;
        info.acceleration_structure_features.accelerationStructure = VK_TRUE;
        info.vulkan12_features.bufferDeviceAddress = VK_TRUE;
        device = vkrc::Device::create(physical_device, info);
        queue = device.default_queue();
        set_layout = vkrc::DescriptorSetLayout::create(
            device, {.bindings = {{.binding = 0,
                                   .descriptor_type = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR,
                                   .stage_flags = VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR},
                                  {.binding = 1,
                                   .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                   .stage_flags = VK_SHADER_STAGE_RAYGEN_BIT_KHR}}});
        layout = vkrc::PipelineLayout::create(device, {.set_layouts = {set_layout}});
        pool = vkrc::DescriptorPool::create(device, {.max_sets = 4,
                                                     .pool_sizes = {{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 4},
                                                                    {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 4}}});
        results = vkrc::Buffer::create(device,
                                       {.size = side * side * 4,
                                        .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                        .memory = {.usage = vkrc::MemoryUsage::readback}});
    }

    vkrc::ShaderModule module(std::span<const std::uint32_t> code) const {
        return vkrc::ShaderModule::create(device, code);
    }

    // The scene's stages and groups; salt specializes the raygen shader.
    vkrc::RayTracingPipelineCreateInfo pipeline_info(const std::uint32_t* salt = nullptr) const {
        static const VkSpecializationMapEntry salt_entry{0, 0, sizeof(std::uint32_t)};
        vkrc::RayTracingPipelineCreateInfo info;
        info.stages = {
            {.stage = VK_SHADER_STAGE_RAYGEN_BIT_KHR, .module = module(vkrc_shaders::rt_scene_rgen)},
            {.stage = VK_SHADER_STAGE_MISS_BIT_KHR, .module = module(vkrc_shaders::rt_scene_rmiss)},
            {.stage = VK_SHADER_STAGE_MISS_BIT_KHR, .module = module(vkrc_shaders::rt_shadow_rmiss)},
            {.stage = VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR, .module = module(vkrc_shaders::rt_scene_rchit)},
            {.stage = VK_SHADER_STAGE_ANY_HIT_BIT_KHR, .module = module(vkrc_shaders::rt_scene_rahit)},
            {.stage = VK_SHADER_STAGE_INTERSECTION_BIT_KHR, .module = module(vkrc_shaders::rt_sphere_rint)},
            {.stage = VK_SHADER_STAGE_CALLABLE_BIT_KHR, .module = module(vkrc_shaders::rt_scene_rcall)},
        };
        if (salt) {
            info.stages[raygen].specialization = {std::span(&salt_entry, 1), std::as_bytes(std::span(salt, 1))};
        }
        info.groups = {
            {.general_shader = raygen},
            {.general_shader = scene_miss},
            {.general_shader = shadow_miss},
            {.type = VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR,
             .closest_hit_shader = closest_hit,
             .any_hit_shader = any_hit},
            {.type = VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR,
             .closest_hit_shader = closest_hit,
             .intersection_shader = intersection},
            {.general_shader = callable},
        };
        info.max_ray_recursion_depth = 2;  // raygen's rays, and the shadow rays of closest hits
        return info;
    }

    vkrc::RayTracingPipeline make_pipeline(const std::uint32_t* salt = nullptr) const {
        return vkrc::RayTracingPipeline::create(layout, pipeline_info(salt));
    }

    // The table of the scene: raygen; the scene's and the shadows' misses;
    // hit records 0 and 1 (triangles, by the quads' sbt_offset) and 2
    // (spheres), each with its tag; the callable.
    static vkrc::ShaderBindingTable make_table(const vkrc::RayTracingPipeline& pipeline,
                                               const Tags& tags = default_tags, vkrc::SharedAllocator allocator = {}) {
        const SphereRecord sphere_record{tags[2], {}, spheres};
        vkrc::ShaderBindingTableCreateInfo info;
        info.raygen = {raygen_group};
        info.miss = {{miss_group, std::as_bytes(std::span(&miss_value, 1))}, {shadow_group}};
        info.hit = {{triangles_group, std::as_bytes(std::span(&tags[0], 1))},
                    {triangles_group, std::as_bytes(std::span(&tags[1], 1))},
                    {spheres_group, std::as_bytes(std::span(&sphere_record, 1))}};
        info.callable = {{callable_group, std::as_bytes(std::span(&callable_bits, 1))}};
        info.allocator = allocator;
        return vkrc::ShaderBindingTable::create(pipeline, info);
    }

    // Builds the quads (non-opaque: the any-hit shader sees them), the
    // spheres' boxes and the top level over them in one submission.
    Scene build_scene() const {
        const std::array<float, 24> corners{0, 0, 0, 4, 0, 0, 4, 4, 0, 0, 4, 0, 4, 0, 0, 8, 0, 0, 8, 4, 0, 4, 4, 0};
        const std::array<std::uint32_t, 12> indices{0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};
        std::array<VkAabbPositionsKHR, 2> boxes{};
        for (std::size_t i = 0; i < spheres.size(); ++i) {
            const auto& s = spheres[i];
            boxes[i] = {s[0] - s[3], s[1] - s[3], s[2] - s[3], s[0] + s[3], s[1] + s[3], s[2] + s[3]};
        }
        const auto vertex_buffer = input_buffer<float>(device, corners, input_usage);
        const auto index_buffer = input_buffer<std::uint32_t>(device, indices, input_usage);
        const auto box_buffer = input_buffer<VkAabbPositionsKHR>(device, boxes, input_usage);
        Scene scene;
        OneShot s(queue);
        vkrc::BottomLevelBuildInfo quads;
        quads.geometries = {
            {.vertex_buffer = vertex_buffer,
             .max_vertex = 7,
             .index_buffer = index_buffer,
             .triangle_count = 2,
             .flags = 0},
            {.vertex_buffer = vertex_buffer,
             .max_vertex = 7,
             .index_buffer = index_buffer,
             .index_offset = 24,
             .triangle_count = 2,
             .flags = 0},
        };
        scene.quads = vkrc::build_bottom_level(s.cmd, quads);
        vkrc::BottomLevelBuildInfo spheres_info;
        spheres_info.aabbs = {{.buffer = box_buffer, .count = 2}};
        scene.boxes = vkrc::build_bottom_level(s.cmd, spheres_info);
        const auto built = vkrc::memory_barrier(
            VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR,
            VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR);
        s.cmd.pipeline_barrier(std::span(&built, 1), {}, {});
        vkrc::TopLevelBuildInfo top;
        top.instances = {
            {.bottom_level = scene.quads, .transform = placed(0.25f, 0, 0), .custom_index = 5, .mask = 0x01},
            {.bottom_level = scene.quads,
             .transform = placed(0.25f, 8, 0),
             .custom_index = 7,
             .mask = 0x01,
             .sbt_offset = 1},
            {.bottom_level = scene.boxes, .custom_index = 9, .mask = 0x01, .sbt_offset = 2},
            {.bottom_level = scene.quads, .transform = placed(0.25f, 2, 5, 2), .custom_index = 13, .mask = 0x02},
        };
        scene.top_level = vkrc::build_top_level(s.cmd, top);
        s.run(queue);
        return scene;
    }

    vkrc::DescriptorSet trace_set(const vkrc::AccelerationStructure& top_level) const {
        auto set = pool.allocate(set_layout);
        set.write_acceleration_structure(0, top_level);
        set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, results);
        return set;
    }

    // Fills results with untouched, then records the trace (trace: the
    // trace_rays or trace_rays_indirect call) between the barriers it needs.
    template <class Trace>
    void record_trace(const vkrc::CommandBuffer& cmd, const vkrc::RayTracingPipeline& pipeline,
                      const vkrc::DescriptorSet& set, Trace trace) const {
        cmd.fill_buffer(results, 0, VK_WHOLE_SIZE, untouched);
        const std::array before{
            vkrc::memory_barrier(VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                                 VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR,
                                 VK_PIPELINE_STAGE_2_RAY_TRACING_SHADER_BIT_KHR,
                                 VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR),
            vkrc::memory_barrier(VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                 VK_PIPELINE_STAGE_2_RAY_TRACING_SHADER_BIT_KHR, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT)};
        cmd.pipeline_barrier(before, {}, {});
        cmd.bind_pipeline(pipeline);
        cmd.bind_descriptor_set(pipeline, 0, set);
        trace(cmd);
        const auto to_host =
            vkrc::memory_barrier(VK_PIPELINE_STAGE_2_RAY_TRACING_SHADER_BIT_KHR, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                 VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
        cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    }

    std::vector<std::uint32_t> read_results() const {
        std::vector<std::uint32_t> out(side * side);
        results.allocation().read(0, out.data(), out.size());
        return out;
    }

    // One 16x16 trace of top_level through pipeline and table; the results.
    std::vector<std::uint32_t> trace(const vkrc::AccelerationStructure& top_level,
                                     const vkrc::RayTracingPipeline& pipeline,
                                     const vkrc::ShaderBindingTable& table) const {
        const auto set = trace_set(top_level);
        OneShot s(queue);
        record_trace(s.cmd, pipeline, set, [&](const vkrc::CommandBuffer& cmd) { cmd.trace_rays(table, side, side); });
        s.run(queue);
        return read_results();
    }

    vkrc::DescriptorSetLayout set_layout;
    vkrc::PipelineLayout layout;
    vkrc::DescriptorPool pool;
    vkrc::Buffer results;
};

TEST_F(RayTracingTest, TracedSceneMatchesTheExpectedHitsShadowsAndRecords) {
    const Scene scene = build_scene();
    const auto pipeline = make_pipeline();
    EXPECT_EQ(pipeline.bind_point(), VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR);
    EXPECT_EQ(pipeline.group_count(), 6u);
    EXPECT_EQ(pipeline.group_region(raygen_group), vkrc::ShaderGroupRegion::raygen);
    EXPECT_EQ(pipeline.group_region(shadow_group), vkrc::ShaderGroupRegion::miss);
    EXPECT_EQ(pipeline.group_region(spheres_group), vkrc::ShaderGroupRegion::hit);
    EXPECT_EQ(pipeline.group_region(callable_group), vkrc::ShaderGroupRegion::callable);
    EXPECT_EQ(pipeline.max_ray_recursion_depth(), 2u);
    const auto table = make_table(pipeline);
    expect_results(trace(scene.top_level, pipeline, table),
                   [](std::uint32_t x, std::uint32_t y) { return expected_value(x, y); });
}

// The layout follows the device's handle size and alignments; raygen's size is its stride.
TEST_F(RayTracingTest, TableLayoutFollowsTheDeviceAlignments) {
    const auto props = vkrc::ray_tracing_pipeline_properties(physical_device);
    const auto pipeline = make_pipeline();
    const auto table = make_table(pipeline);
    EXPECT_EQ(pipeline.use_count(), 2u) << "the test's handle and the table's";
    const auto align = [](VkDeviceSize v, VkDeviceSize a) { return (v + a - 1) / a * a; };
    const VkDeviceSize handle = props.shaderGroupHandleSize;
    const VkDeviceSize expected_strides[] = {align(handle, props.shaderGroupHandleAlignment),
                                             align(handle + 4, props.shaderGroupHandleAlignment),
                                             align(handle + sizeof(SphereRecord), props.shaderGroupHandleAlignment),
                                             align(handle + 4, props.shaderGroupHandleAlignment)};
    const VkDeviceSize counts[] = {1, 2, 3, 1};
    for (int r = 0; r < 4; ++r) {
        const VkStridedDeviceAddressRegionKHR& region = table.regions()[r];
        SCOPED_TRACE(r);
        EXPECT_EQ(region.deviceAddress % props.shaderGroupBaseAlignment, 0u);
        EXPECT_EQ(region.stride, expected_strides[r]);
        EXPECT_EQ(region.size, expected_strides[r] * counts[r]);
        EXPECT_GE(region.deviceAddress, table.buffer().device_address());
        EXPECT_LE(region.deviceAddress + region.size, table.buffer().device_address() + table.buffer().size());
    }
    EXPECT_EQ(table.raygen_region().size, table.raygen_region().stride);
    EXPECT_TRUE(table.buffer().usage() & VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR);
}

// Another table over the same pipeline with other tags in its hit records:
// the instances' sbt_offset select them, so the output follows.
TEST_F(RayTracingTest, HitRecordDataSelectedByInstanceOffsetsChangesTheOutput) {
    const Scene scene = build_scene();
    const auto pipeline = make_pipeline();
    const Tags other{4, 6, 5};
    const auto results = trace(scene.top_level, pipeline, make_table(pipeline, other));
    expect_results(results, [&](std::uint32_t x, std::uint32_t y) { return expected_value(x, y, other); });
    EXPECT_NE(results, trace(scene.top_level, pipeline, make_table(pipeline)));
}

// A specialization constant of the raygen stage changes every pixel.
TEST_F(RayTracingTest, SpecializationConstantChangesTheOutput) {
    const Scene scene = build_scene();
    const std::uint32_t salt = 0x5A5A5A5Au;
    const auto pipeline = make_pipeline(&salt);
    expect_results(trace(scene.top_level, pipeline, make_table(pipeline)),
                   [&](std::uint32_t x, std::uint32_t y) { return expected_value(x, y, default_tags, salt); });
}

// trace_rays_indirect reads the launch size (8x16) from a buffer by address:
// the right half stays as filled.
TEST_F(RayTracingTest, IndirectTraceReadsItsDimensionsFromABuffer) {
    const Scene scene = build_scene();
    const auto pipeline = make_pipeline();
    const auto table = make_table(pipeline);
    const VkTraceRaysIndirectCommandKHR size{side / 2, side, 1};
    const auto indirect = input_buffer<VkTraceRaysIndirectCommandKHR>(
        device, std::span(&size, 1), VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
    const auto set = trace_set(scene.top_level);
    OneShot s(queue);
    record_trace(s.cmd, pipeline, set,
                 [&](const vkrc::CommandBuffer& cmd) { cmd.trace_rays_indirect(table, indirect.device_address()); });
    s.run(queue);
    expect_results(
        read_results(), [](std::uint32_t x, std::uint32_t y) { return expected_value(x, y); }, side / 2);
}

// The table, the pipeline, the top level and its bottom levels, and the set,
// dropped while the trace waits behind a gate the host opens: each waits for
// the work (deferred destruction), which then traces the whole scene.
TEST_F(RayTracingTest, DroppedTablePipelineAndStructuresLiveUntilGatedWorkTracesThem) {
    vkrc_test::GpuGate gate(device);
    auto commands = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = commands.allocate();
    auto fence = vkrc::Fence::create(device);
    {
        Scene scene = build_scene();
        auto pipeline = make_pipeline();
        auto table = make_table(pipeline);
        auto set = trace_set(scene.top_level);
        cmd.begin();
        record_trace(cmd, pipeline, set, [&](const vkrc::CommandBuffer& c) { c.trace_rays(table, side, side); });
        cmd.end();
        gate.submit(queue, cmd, fence);
        const std::size_t before = device.deferred_count();
        table.reset();
        pipeline.reset();
        set.reset();
        scene.top_level.reset();
        scene.quads.reset();
        scene.boxes.reset();
        cmd.reset();
        EXPECT_GT(device.deferred_count(), before) << "the dropped objects wait for the gated trace";
    }
    gate.open();
    ASSERT_EQ(fence.wait(), VK_SUCCESS);
    expect_results(read_results(), [](std::uint32_t x, std::uint32_t y) { return expected_value(x, y); });
    device.collect_garbage();
}

// Seeded rounds (VKRC_TEST_SEED replays one): each reuses or makes the
// levels, the pipeline (a new one with one of two salts) and the table (new
// hit tags, from an allocator counting its frees), records a trace behind a
// gate the host opens, and drops a random subset of the table, the
// pipeline, the top level, the bottom levels and the set, each at a random
// point before or after the submit. Until the gate opens no table memory
// may be freed; every round reads back the whole expected scene.
TEST_F(RayTracingTest, RandomDropsOfTablesPipelinesAndStructuresWithTracesInFlight) {
    const auto seed = vkrc_test::test_seed();
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937 rng(seed);
    const auto pick = [&](std::uint32_t n) { return std::uniform_int_distribution<std::uint32_t>(0, n - 1)(rng); };
    enum Slot { after_record, after_end, after_submit, kept, slots };
    std::array<int, slots> coverage{};
    // A few sets of tags only: with fresh random ones lavapipe runs took
    // seconds more (cold shader cache, it seemed), with these a few hundred ms.
    const std::array<Tags, 3> tag_choices{default_tags, Tags{4, 6, 5}, Tags{15, 9, 12}};
    Scene scene;
    vkrc::RayTracingPipeline pipeline;
    vkrc::ShaderBindingTable table;
    // The table's own: it frees nothing until the table and all work with it are gone.
    decltype(vkrc::make_allocator<vkrc_test::CountingAllocator>()) table_allocator;
    std::uint32_t salt = 0;
    Tags tags = default_tags;
    auto commands = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    for (int round = 0; round < 12; ++round) {
        SCOPED_TRACE("round " + std::to_string(round));
        if (!scene.top_level || pick(4) == 0) scene = build_scene();
        if (!pipeline || pick(4) == 0) {
            // Two salts only: each new one costs lavapipe a shader compile of seconds.
            salt = pick(2) ? 0 : 0x5A5A5A5Au;
            pipeline = make_pipeline(&salt);
            table = {};  // a table is of one pipeline
        }
        if (!table || pick(2) == 0) {
            tags = tag_choices[pick(tag_choices.size())];
            table_allocator = vkrc::make_allocator<vkrc_test::CountingAllocator>();
            table = make_table(pipeline, tags, table_allocator);
        }
        auto set = trace_set(scene.top_level);
        std::vector<std::pair<std::function<void()>, Slot>> drops;
        const auto add = [&](std::function<void()> drop) { drops.emplace_back(std::move(drop), Slot(pick(slots))); };
        add([&] { table = {}; });
        add([&] { pipeline = {}; });
        add([&] { scene.top_level = {}; });
        add([&] { scene.quads = {}, scene.boxes = {}; });
        add([&] { set = {}; });
        std::shuffle(drops.begin(), drops.end(), rng);
        const auto drop_at = [&](Slot slot) {
            for (auto& [drop, at] : drops) {
                if (at == slot) drop();
            }
        };
        for (const auto& drop : drops) ++coverage[drop.second];
        vkrc_test::GpuGate gate(device);
        auto cmd = commands.allocate();
        auto fence = vkrc::Fence::create(device);
        cmd.begin();
        record_trace(cmd, pipeline, set, [&](const vkrc::CommandBuffer& c) { c.trace_rays(table, side, side); });
        drop_at(after_record);
        cmd.end();
        drop_at(after_end);
        gate.submit(queue, cmd, fence);
        drop_at(after_submit);
        EXPECT_EQ(table_allocator->frees(), 0) << "table memory freed while a trace of it was held";
        gate.open();
        ASSERT_EQ(fence.wait(), VK_SUCCESS);
        expect_results(read_results(),
                       [&](std::uint32_t x, std::uint32_t y) { return expected_value(x, y, tags, salt); });
        if (HasFailure()) return;
    }
    std::printf("drops after the record %d, after end %d, after submit %d; kept %d\n", coverage[after_record],
                coverage[after_end], coverage[after_submit], coverage[kept]);
    for (int c : coverage) EXPECT_GT(c, 0);
    device.wait_idle();
    device.collect_garbage();
    EXPECT_EQ(device.deferred_count(), 0u);
}

TEST_F(RayTracingTest, BadPipelinesAreRefused) {
    const auto refusal = [&](auto&& change) {
        auto info = pipeline_info();
        change(info);
        return usage_error_of([&] { vkrc::RayTracingPipeline::create(layout, info); });
    };
    const std::string who = "vkrc::RayTracingPipeline::create: ";
    EXPECT_EQ(refusal([](auto& i) { i.groups[1].general_shader = 9; }),
              who + "groups[1].general_shader 9 is out of range (7 stages)");
    EXPECT_EQ(refusal([](auto& i) { i.groups[3].closest_hit_shader = scene_miss; }),
              who +
                  "groups[3].closest_hit_shader is stages[1], a VK_SHADER_STAGE_MISS_BIT_KHR shader; it must be a "
                  "CLOSEST_HIT shader");
    EXPECT_EQ(refusal([](auto& i) { i.groups[0].closest_hit_shader = closest_hit; }),
              who +
                  "groups[0] (VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR) has a closest_hit_shader, which its "
                  "type does not take (VK_SHADER_UNUSED_KHR)");
    EXPECT_EQ(refusal([](auto& i) { i.groups[4].intersection_shader = VK_SHADER_UNUSED_KHR; }),
              who + "groups[4] is PROCEDURAL_HIT_GROUP without an intersection_shader");
    EXPECT_EQ(refusal([](auto& i) { i.groups[5].general_shader = any_hit; }),
              who +
                  "groups[5].general_shader is stages[4], a VK_SHADER_STAGE_ANY_HIT_BIT_KHR shader; it must be a "
                  "RAYGEN, MISS or CALLABLE shader");
    EXPECT_EQ(refusal([](auto& i) { i.stages[callable].stage = VK_SHADER_STAGE_COMPUTE_BIT; }),
              who +
                  "stages[6].stage 0x20 is not one ray tracing stage (RAYGEN, MISS, CLOSEST_HIT, ANY_HIT, "
                  "INTERSECTION or CALLABLE)");
    EXPECT_EQ(refusal([](auto& i) { i.groups.clear(); }), who + "groups is empty");
    EXPECT_EQ(refusal([](auto& i) { i.flags = VK_PIPELINE_CREATE_LIBRARY_BIT_KHR; }),
              who + "flags has LIBRARY_BIT_KHR: pipeline libraries are not supported");
    const std::uint32_t max = vkrc::ray_tracing_pipeline_properties(physical_device).maxRayRecursionDepth;
    EXPECT_EQ(refusal([&](auto& i) { i.max_ray_recursion_depth = max + 1; }),
              who + "max_ray_recursion_depth " + std::to_string(max + 1) +
                  " exceeds the device's maxRayRecursionDepth " + std::to_string(max));
}

TEST_F(RayTracingTest, BadTablesAreRefused) {
    const auto pipeline = make_pipeline();
    const auto props = vkrc::ray_tracing_pipeline_properties(physical_device);
    const std::string who = "vkrc::ShaderBindingTable::create: ";
    const auto refusal = [&](vkrc::ShaderBindingTableCreateInfo info) {
        return usage_error_of([&] { vkrc::ShaderBindingTable::create(pipeline, info); });
    };
    EXPECT_EQ(refusal({.raygen = {miss_group}}), who + "raygen[0]: group 1 is a miss group, not a raygen group");
    EXPECT_EQ(refusal({.hit = {{triangles_group}, {callable_group}}}),
              who + "hit[1]: group 5 is a callable group, not a hit group");
    EXPECT_EQ(refusal({.callable = {{6}}}), who + "callable[0]: group 6 is out of range (6 groups)");
    const std::vector<std::byte> too_much(props.maxShaderGroupStride);
    const VkDeviceSize record = props.shaderGroupHandleSize + too_much.size();
    const VkDeviceSize stride = (record + props.shaderGroupHandleAlignment - 1) / props.shaderGroupHandleAlignment *
                                props.shaderGroupHandleAlignment;
    EXPECT_EQ(refusal({.miss = {{miss_group, too_much}}}),
              who + "miss: a record of " + std::to_string(record) + " bytes (stride " + std::to_string(stride) +
                  ") exceeds the device's maxShaderGroupStride " + std::to_string(props.maxShaderGroupStride));
}

TEST_F(RayTracingTest, BadBoxGeometryIsRefused) {
    const std::array<VkAabbPositionsKHR, 1> box{{{0, 0, 0, 1, 1, 1}}};
    const auto boxes = input_buffer<VkAabbPositionsKHR>(device, box, input_usage);
    const std::array<float, 9> corners{0, 0, 0, 1, 0, 0, 0, 1, 0};
    const auto vertices = input_buffer<float>(device, corners, input_usage);
    OneShot s(queue);
    const auto refusal = [&](const vkrc::BottomLevelBuildInfo& info) {
        return usage_error_of([&] { vkrc::build_bottom_level(s.cmd, info); });
    };
    const std::string who = "vkrc::build_bottom_level: ";
    vkrc::BottomLevelBuildInfo info;
    info.geometries = {{.vertex_buffer = vertices, .max_vertex = 2, .triangle_count = 1}};
    info.aabbs = {{.buffer = boxes, .count = 1}};
    EXPECT_EQ(refusal(info),
              who + "geometries and aabbs are both set; a bottom level holds triangles or boxes, not both");
    info.geometries.clear();
    info.aabbs[0].count = 2;
    EXPECT_EQ(refusal(info), who + "aabbs[0]: 2 boxes at stride 24 from offset 0 need 48 bytes, the buffer has 24");
    info.aabbs[0] = {.buffer = boxes, .offset = 4, .count = 1};
    EXPECT_EQ(refusal(info), who + "aabbs[0] has offset 4; it must be a multiple of 8");
    info.aabbs[0] = {.buffer = boxes, .stride = 28, .count = 1};
    EXPECT_EQ(refusal(info), who + "aabbs[0] has stride 28; it must be a multiple of 8, at least 24");
    info.aabbs[0] = {.buffer = boxes};
    EXPECT_EQ(refusal(info), who + "aabbs[0] has count 0");
    info.aabbs.clear();
    EXPECT_EQ(refusal(info), who + "geometries and aabbs are both empty");
    s.run(queue);
}

// Devices without what ray tracing pipelines need: create says what is missing.
using RayTracingRefusal = VulkanTest;

// The fixture's plain device, made without VK_KHR_ray_tracing_pipeline.
TEST_F(RayTracingRefusal, WithoutTheExtensionPipelinesAreRefused) {
    const auto layout = vkrc::PipelineLayout::create(device);
    EXPECT_EQ(usage_error_of([&] { vkrc::RayTracingPipeline::create(layout, {}); }),
              "vkrc::RayTracingPipeline::create: ray tracing pipelines need VK_KHR_ray_tracing_pipeline enabled on the "
              "device (set DeviceCreateInfo::ray_tracing_pipeline_features.rayTracingPipeline)");
}

// The extensions enabled without the rayTracingPipeline feature: refused, naming the feature.
TEST_F(RayTracingRefusal, WithoutTheFeaturePipelinesAreRefused) {
    if (!physical_device.supports_extension(VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME))
        GTEST_SKIP() << "the device lacks VK_KHR_ray_tracing_pipeline";
    vkrc::DeviceCreateInfo info;
    info.enabled_extension_names = {VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME,
                                    VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                                    VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};
    device = vkrc::Device::create(physical_device, info);
    queue = device.default_queue();
    const auto layout = vkrc::PipelineLayout::create(device);
    EXPECT_EQ(usage_error_of([&] { vkrc::RayTracingPipeline::create(layout, {}); }),
              "vkrc::RayTracingPipeline::create: ray tracing pipelines need the rayTracingPipeline feature enabled");
}

// select() reads the extension's features and names a missing one.
TEST_F(RayTracingRefusal, RequirementsNameTheMissingFeature) {
    vkrc::DeviceRequirements wanted = vkrc_test::test_device_requirements();
    wanted.required_features.ray_tracing_pipeline.rayTracingPipelineShaderGroupHandleCaptureReplayMixed = VK_TRUE;
    vkrc_test::expect_requirement_named(
        physical_device, wanted,
        physical_device.features().ray_tracing_pipeline.rayTracingPipelineShaderGroupHandleCaptureReplayMixed,
        "lacks feature rayTracingPipelineShaderGroupHandleCaptureReplayMixed (VK_KHR_ray_tracing_pipeline)");
}

}  // namespace
