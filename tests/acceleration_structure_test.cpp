// Acceleration structures: bottom levels built from triangles, top levels
// from instances of them, traced with a ray query (shaders/ray_query.comp,
// and from a fragment shader, shaders/ray_query.frag) and checked pixel by
// pixel; the top level keeping its bottom levels alive
// after their handles are dropped, rebuilds that release the old ones, refits,
// descriptors of acceleration structures, and the refusals.
#include "support/acceleration_structures.hpp"
#include "support/features.hpp"
#include "support/vk_test.hpp"

#include "shaders/fullscreen.vert.h"
#include "shaders/ray_query.comp.h"
#include "shaders/ray_query.frag.h"

#include <array>
#include <span>
#include <string>
#include <vector>

namespace {

using vkrc_test::barrier_between_levels;
using vkrc_test::build_input;
using vkrc_test::built_to;
using vkrc_test::placed;
using vkrc_test::usage_error_of;
using vkrc_test::VulkanTest;

constexpr std::uint32_t width = 16;
constexpr std::uint32_t height = 16;
constexpr std::uint32_t miss = 0xFFFFFFFFu;

struct Params {
    std::uint32_t width;
    std::uint32_t height;
    std::uint32_t cull_mask;
};

// What the ray of pixel (x, y) reports: custom index << 8 | geometry index.
constexpr std::uint32_t hit(std::uint32_t custom_index, std::uint32_t geometry) { return custom_index << 8 | geometry; }

// The geometry the tests build from, kept by handles a test may drop.
struct Inputs {
    vkrc::Buffer square;       // 4 vertices: the square [0,4]x[0,4] at z 0
    vkrc::Buffer indices32;    // its two triangles, 32-bit indices
    vkrc::Buffer indices16;    // the same, 16-bit
    vkrc::Buffer shift_right;  // a VkTransformMatrixKHR: x + 4
    vkrc::Buffer triangle;     // 3 vertices: (0,0), (4.2,0), (0,4.2), not indexed
};

Inputs make_inputs(const vkrc::Device& device) {
    Inputs in;
    in.square = build_input<float>(device, {0, 0, 0, 4, 0, 0, 4, 4, 0, 0, 4, 0});
    in.indices32 = build_input<std::uint32_t>(device, {0, 1, 2, 0, 2, 3});
    in.indices16 = build_input<std::uint16_t>(device, {0, 1, 2, 0, 2, 3, 0, 0});  // padded to 16 bytes
    const VkTransformMatrixKHR shift = placed(4, 0, 0);
    in.shift_right = build_input<float>(device, std::vector<float>(&shift.matrix[0][0], &shift.matrix[0][0] + 12));
    in.triangle = build_input<float>(device, {0, 0, 0, 4.2f, 0, 0, 0, 4.2f, 0});
    return in;
}

// Two geometries: geometry 0 the square [0,4]x[0,4], geometry 1 the same
// square moved by its transform to [4,8]x[0,4] (16-bit indices).
vkrc::BottomLevelBuildInfo squares_info(const Inputs& in, VkBuildAccelerationStructureFlagsKHR flags = 0) {
    vkrc::BottomLevelBuildInfo info;
    info.flags = flags;
    info.geometries = {
        {.vertex_buffer = in.square, .max_vertex = 3, .index_buffer = in.indices32, .triangle_count = 2},
        {.vertex_buffer = in.square,
         .max_vertex = 3,
         .index_buffer = in.indices16,
         .index_type = VK_INDEX_TYPE_UINT16,
         .triangle_count = 2,
         .transform_buffer = in.shift_right,
         .flags = VK_GEOMETRY_OPAQUE_BIT_KHR | VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT_KHR},
    };
    return info;
}

vkrc::BottomLevelBuildInfo triangle_info(const Inputs& in) {
    vkrc::BottomLevelBuildInfo info;
    info.geometries = {{.vertex_buffer = in.triangle, .max_vertex = 2, .triangle_count = 1}};
    return info;
}

// The scene's instances: squares twice (custom 5 in place, custom 7 moved up
// by 8), the triangle twice (custom 9 scaled by 2 at (8,8); custom 11 at z 1,
// in front of the first squares), and custom 13 that only mask 0x02 sees.
vkrc::TopLevelBuildInfo scene_info(const vkrc::AccelerationStructure& squares,
                                   const vkrc::AccelerationStructure& triangle) {
    vkrc::TopLevelBuildInfo info;
    info.instances = {
        {.bottom_level = squares, .custom_index = 5},
        {.bottom_level = squares, .transform = placed(0, 8, 0), .custom_index = 7},
        {.bottom_level = triangle, .transform = placed(8, 8, 0, 2), .custom_index = 9, .sbt_offset = 1},
        {.bottom_level = triangle,
         .transform = placed(0, 0, 1),
         .custom_index = 11,
         .flags = VK_GEOMETRY_INSTANCE_TRIANGLE_FACING_CULL_DISABLE_BIT_KHR},
        {.bottom_level = squares, .transform = placed(12, 12, 0), .custom_index = 13, .mask = 0x02},
    };
    return info;
}

// scene_info's expected hits: the closest instance along -z (the ray starts
// at z 10), none of the pixel centres on an outer edge.
std::uint32_t expected_scene(std::uint32_t x, std::uint32_t y) {
    const float cx = float(x) + 0.5f, cy = float(y) + 0.5f;
    if (cx + cy < 4.2f) return hit(11, 0);
    if (cy < 4 && cx < 8) return hit(5, cx < 4 ? 0 : 1);
    if (cy > 8 && cy < 12 && cx < 8) return hit(7, cx < 4 ? 0 : 1);
    if (cx > 8 && cy > 8 && (cx - 8) + (cy - 8) < 8.4f) return hit(9, 0);
    return miss;
}

// expected_scene's with mask 0x03, which also sees custom 13, the squares at
// (12,12) the default mask misses.
std::uint32_t expected_scene_both_masks(std::uint32_t x, std::uint32_t y) {
    const float cx = float(x) + 0.5f, cy = float(y) + 0.5f;
    if (cx > 12 && cy > 12 && cy < 16 && cx < 20) return hit(13, cx < 16 ? 0 : 1);
    return expected_scene(x, y);
}

// Compares hits with expected(x, y) and names the first pixels that differ.
template <class Expected>
void expect_hits(const std::vector<std::uint32_t>& hits, Expected expected) {
    int wrong = 0;
    for (std::uint32_t y = 0; y < height; ++y) {
        for (std::uint32_t x = 0; x < width; ++x) {
            const std::uint32_t want = expected(x, y), got = hits[y * width + x];
            if (got != want && ++wrong <= 5) {
                ADD_FAILURE() << "pixel (" << x << ", " << y << "): got 0x" << std::hex << got << ", expected 0x"
                              << want;
            }
        }
    }
    EXPECT_EQ(wrong, 0) << "pixels wrong";
}

class AccelerationStructureTest : public vkrc_test::RayQueryTest {
protected:
    void SetUp() override {
        RayQueryTest::SetUp();
        if (HasFatalFailure() || IsSkipped()) return;
        make_tracer();
    }

    void make_tracer() {
        set_layout = vkrc::DescriptorSetLayout::create(
            device, {.bindings = {{.binding = 0, .descriptor_type = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR},
                                  {.binding = 1, .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}}});
        layout = vkrc::PipelineLayout::create(
            device,
            {.set_layouts = {set_layout}, .push_constant_ranges = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(Params)}}});
        pipeline =
            vkrc::ComputePipeline::create(layout, vkrc::ShaderModule::create(device, vkrc_shaders::ray_query_comp));
        pool = vkrc::DescriptorPool::create(device, {.max_sets = 4,
                                                     .pool_sizes = {{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 4},
                                                                    {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 4}}});
        hits = vkrc::Buffer::create(device,
                                    {.size = width * height * 4,
                                     .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                     .memory = {.usage = vkrc::MemoryUsage::readback}});
    }

    // A set whose binding 0 holds top_level (written here) and binding 1 the hits buffer.
    vkrc::DescriptorSet trace_set(const vkrc::AccelerationStructure& top_level) const {
        auto set = pool.allocate(set_layout);
        set.write_acceleration_structure(0, top_level);
        set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, hits);
        return set;
    }

    // Records the trace through set: a barrier from the builds before, one to the host after.
    void record_trace(const vkrc::CommandBuffer& cmd, const vkrc::DescriptorSet& set,
                      std::uint32_t cull_mask = 0x01) const {
        const auto built =
            built_to(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR);
        cmd.pipeline_barrier(std::span(&built, 1), {}, {});
        cmd.bind_pipeline(pipeline);
        cmd.bind_descriptor_set(pipeline, 0, set);
        cmd.push_constants(layout, VK_SHADER_STAGE_COMPUTE_BIT, Params{width, height, cull_mask});
        cmd.dispatch(width / 8, height / 8);
        const auto to_host = vkrc_test::compute_to_host();
        cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
    }

    std::vector<std::uint32_t> read_hits() const {
        std::vector<std::uint32_t> out(width * height);
        hits.allocation().read(0, out.data(), out.size());
        return out;
    }

    // Builds squares and triangle and the scene over them in one submission.
    vkrc::AccelerationStructure build_scene(const Inputs& in, vkrc::AccelerationStructure* squares_out = nullptr,
                                            vkrc::AccelerationStructure* triangle_out = nullptr) const {
        vkrc_test::OneShotCommands s(queue);
        auto squares = vkrc::build_bottom_level(s.cmd, squares_info(in));
        auto triangle = vkrc::build_bottom_level(s.cmd, triangle_info(in));
        barrier_between_levels(s.cmd);
        auto scene = vkrc::build_top_level(s.cmd, scene_info(squares, triangle));
        s.run(queue);
        if (squares_out) *squares_out = squares;
        if (triangle_out) *triangle_out = triangle;
        return scene;
    }

    // Traces scene once (mask cull_mask) and returns the hits.
    std::vector<std::uint32_t> trace(const vkrc::AccelerationStructure& scene, std::uint32_t cull_mask = 0x01) const {
        auto set = trace_set(scene);
        vkrc_test::OneShotCommands s(queue);
        record_trace(s.cmd, set, cull_mask);
        s.run(queue);
        return read_hits();
    }

    vkrc::DescriptorSetLayout set_layout;
    vkrc::PipelineLayout layout;
    vkrc::ComputePipeline pipeline;
    vkrc::DescriptorPool pool;
    vkrc::Buffer hits;
};

TEST_F(AccelerationStructureTest, TracedHitsMatchTheGeometryAndTheInstanceTransforms) {
    const Inputs in = make_inputs(device);
    vkrc::AccelerationStructure squares, triangle;
    auto scene = build_scene(in, &squares, &triangle);
    EXPECT_EQ(scene.type(), VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR);
    EXPECT_EQ(squares.type(), VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
    EXPECT_NE(scene.device_address(), 0u);
    EXPECT_GE(scene.buffer().size(), scene.size());
    ASSERT_EQ(scene.bottom_levels().size(), 5u) << "one kept bottom level per instance";
    expect_hits(trace(scene), expected_scene);
    expect_hits(trace(scene, 0x03), expected_scene_both_masks);
}

// ray_query.frag traces the scene per pixel of a full-screen triangle into
// an R32_UINT attachment (cleared to a value no pixel may keep): every
// pixel as the compute trace's and the CPU's expectation, with either mask.
TEST_F(AccelerationStructureTest, FragmentShaderRayQueriesMatchTheExpectedHits) {
    const Inputs in = make_inputs(device);
    const auto scene = build_scene(in);
    const auto frag_layout = vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{.binding = 0,
                               .descriptor_type = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR,
                               .stage_flags = VK_SHADER_STAGE_FRAGMENT_BIT}}});
    auto set = pool.allocate(frag_layout);
    set.write_acceleration_structure(0, scene);
    const auto render_pass = vkrc_test::clear_to_copy_render_pass(device, VK_FORMAT_R32_UINT);
    const auto image =
        vkrc::Image::create(device, {.format = VK_FORMAT_R32_UINT,
                                     .extent = {width, height, 1},
                                     .usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
    const auto framebuffer = vkrc::Framebuffer::create(device, {.render_pass = render_pass,
                                                                .attachments = {vkrc::ImageView::create(image)},
                                                                .width = width,
                                                                .height = height});
    const auto pipeline =
        vkrc::GraphicsPipelineBuilder(
            vkrc::PipelineLayout::create(
                device, {.set_layouts = {frag_layout},
                         .push_constant_ranges = {{VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(std::uint32_t)}}}))
            .shader(VK_SHADER_STAGE_VERTEX_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::fullscreen_vert))
            .shader(VK_SHADER_STAGE_FRAGMENT_BIT, vkrc::ShaderModule::create(device, vkrc_shaders::ray_query_frag))
            .cull_mode(VK_CULL_MODE_NONE)  // the full-viewport triangle is clockwise
            .render_pass(render_pass)
            .build();
    const auto draw = [&](std::uint32_t cull_mask) {
        vkrc_test::OneShotCommands s(queue);
        const auto built =
            built_to(VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR);
        s.cmd.pipeline_barrier(std::span(&built, 1), {}, {});
        VkClearValue clear{};
        clear.color.uint32[0] = 0xC1EA4ED0u;
        s.cmd.begin_render_pass(render_pass, framebuffer, {{0, 0}, {width, height}}, std::span(&clear, 1));
        s.cmd.bind_pipeline(pipeline);
        s.cmd.bind_descriptor_set(pipeline, 0, set);
        s.cmd.push_constants(pipeline.layout(), VK_SHADER_STAGE_FRAGMENT_BIT, cull_mask);
        s.cmd.set_viewport_and_scissor(framebuffer.extent());
        s.cmd.draw(3);
        s.cmd.end_render_pass();
        vkrc_test::record_readback(s.cmd, image.vk(), hits.vk(), width, height);
        s.run(queue);
        return read_hits();
    };
    const auto drawn = draw(0x01);
    expect_hits(drawn, expected_scene);
    EXPECT_EQ(drawn, trace(scene)) << "the fragment and compute traces differ";
    expect_hits(draw(0x03), expected_scene_both_masks);
}

// The edge no other wrapper tracks: the top level alone keeps its bottom
// levels (and so their memory) once their handles and the geometry are
// gone, while gated work traces through them.
TEST_F(AccelerationStructureTest, TopLevelKeepsItsBottomLevelsAliveWhileGatedWorkTracesThem) {
    vkrc::AccelerationStructure scene;
    {
        vkrc::AccelerationStructure squares, triangle;
        Inputs in = make_inputs(device);
        scene = build_scene(in, &squares, &triangle);
        EXPECT_EQ(squares.use_count(), 1u + 3u) << "this handle and the scene's three instances of it";
    }  // the bottom levels' handles and the vertex, index and transform buffers go here
    auto set = trace_set(scene);
    scene.reset();  // the set keeps the top level, the top level its bottom levels
    vkrc_test::GpuGate gate(device);
    auto pool_of_commands = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool_of_commands.allocate();
    cmd.begin();
    record_trace(cmd, set);
    cmd.end();
    auto fence = vkrc::Fence::create(device);
    gate.submit(queue, cmd, fence);
    set.reset();  // now only the submitted work refers to the scene
    cmd.reset();
    EXPECT_GT(device.deferred_count(), 0u) << "the scene waits for the gated trace";
    gate.open();
    ASSERT_EQ(fence.wait(), VK_SUCCESS);
    expect_hits(read_hits(), expected_scene);
    device.collect_garbage();
}

// A rebuild with other bottom levels traces the new ones and releases the
// old ones (their destruction deferred as a drop's).
TEST_F(AccelerationStructureTest, RebuildReplacesTheKeptBottomLevels) {
    const Inputs in = make_inputs(device);
    vkrc::AccelerationStructure squares, triangle;
    auto scene = build_scene(in, &squares, &triangle);
    expect_hits(trace(scene), expected_scene);
    EXPECT_EQ(triangle.use_count(), 3u);
    {
        vkrc_test::OneShotCommands s(queue);
        // Only the triangle, at the origin, custom 21; the squares are gone from the scene.
        vkrc::TopLevelBuildInfo info;
        info.instances = {{.bottom_level = triangle, .custom_index = 21}};
        vkrc::rebuild_top_level(s.cmd, scene, info);
        s.run(queue);
    }
    EXPECT_EQ(squares.use_count(), 1u) << "the rebuild released the squares";
    EXPECT_EQ(triangle.use_count(), 2u);
    ASSERT_EQ(scene.bottom_levels().size(), 1u);
    EXPECT_TRUE(scene.bottom_levels()[0] == triangle);
    expect_hits(trace(scene),
                [](std::uint32_t x, std::uint32_t y) { return float(x) + float(y) + 1.0f < 4.2f ? hit(21, 0) : miss; });
}

// A rebuild recorded while gated work still traces the old build: the old
// bottom level, its handle dropped, waits for that work (deferred
// destruction), and the gated trace still sees the old scene.
TEST_F(AccelerationStructureTest, RebuildReleasesTheOldBottomLevelsAfterTheWorkInFlight) {
    vkrc::AccelerationStructure scene, triangle;
    {
        const Inputs in = make_inputs(device);
        scene = build_scene(in, nullptr, &triangle);
    }  // the squares are now kept by the scene alone
    auto set = trace_set(scene);
    vkrc_test::GpuGate gate(device);
    auto commands = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto trace_cmd = commands.allocate();
    trace_cmd.begin();
    record_trace(trace_cmd, set);
    trace_cmd.end();
    auto traced = vkrc::Fence::create(device);
    gate.submit(queue, trace_cmd, traced);
    const std::size_t before = device.deferred_count();
    vkrc_test::OneShotCommands s(queue);
    // The rebuild writes what the gated trace reads: after it in submission order.
    const auto after_trace = vkrc::memory_barrier(
        VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR,
        VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, VK_ACCESS_2_ACCELERATION_STRUCTURE_WRITE_BIT_KHR);
    s.cmd.pipeline_barrier(std::span(&after_trace, 1), {}, {});
    vkrc::TopLevelBuildInfo info;
    info.instances = {{.bottom_level = triangle, .custom_index = 21}};
    vkrc::rebuild_top_level(s.cmd, scene, info);
    s.cmd.end();
    auto rebuilt = vkrc::Fence::create(device);
    vkrc::submit(queue, {.command_buffers = std::span(&s.cmd, 1)}, rebuilt);
    EXPECT_GT(device.deferred_count(), before) << "the released squares (with the build's scratch and instances) wait";
    gate.open();
    ASSERT_EQ(traced.wait(), VK_SUCCESS);
    expect_hits(read_hits(), expected_scene);
    ASSERT_EQ(rebuilt.wait(), VK_SUCCESS);
    expect_hits(trace(scene),
                [](std::uint32_t x, std::uint32_t y) { return float(x) + float(y) + 1.0f < 4.2f ? hit(21, 0) : miss; });
}

// Refit: the squares' vertices move by +8 in y, update_bottom_level refits
// in place and a rebuild of the top level takes the new bounds.
TEST_F(AccelerationStructureTest, UpdateRefitsMovedVertices) {
    const Inputs in = make_inputs(device);
    vkrc::AccelerationStructure squares;
    vkrc::AccelerationStructure scene;
    vkrc::TopLevelBuildInfo top;
    {
        vkrc_test::OneShotCommands s(queue);
        squares =
            vkrc::build_bottom_level(s.cmd, squares_info(in, VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR));
        barrier_between_levels(s.cmd);
        top.instances = {{.bottom_level = squares, .custom_index = 3}};
        scene = vkrc::build_top_level(s.cmd, top);
        s.run(queue);
    }
    expect_hits(trace(scene), [](std::uint32_t x, std::uint32_t y) { return y < 4 && x < 8 ? hit(3, x / 4) : miss; });
    const std::vector<float> moved{0, 8, 0, 4, 8, 0, 4, 12, 0, 0, 12, 0};
    in.square.allocation().write(0, moved.data(), moved.size());
    {
        vkrc_test::OneShotCommands s(queue);
        vkrc::update_bottom_level(s.cmd, squares,
                                  squares_info(in, VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR));
        barrier_between_levels(s.cmd);
        vkrc::rebuild_top_level(s.cmd, scene, top);
        s.run(queue);
    }
    expect_hits(trace(scene),
                [](std::uint32_t x, std::uint32_t y) { return y >= 8 && y < 12 && x < 8 ? hit(3, x / 4) : miss; });
}

// The compacted size of structure, written into query 0 of pool by a submission of its own.
VkDeviceSize compacted_size(const vkrc::Queue& queue, const vkrc::QueryPool& pool,
                            const vkrc::AccelerationStructure& structure) {
    vkrc_test::OneShotCommands s(queue);
    barrier_between_levels(s.cmd);  // the build (earlier) before the query reads it
    s.cmd.reset_query_pool(pool, 0, 1);
    const VkAccelerationStructureKHR raw = structure.vk();
    s.cmd.write_acceleration_structures_properties(std::span(&raw, 1),
                                                   VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, pool, 0);
    s.run(queue);
    std::array<std::uint64_t, 1> size{};
    EXPECT_EQ(pool.results(0, std::span(size)), VK_SUCCESS);
    return size[0];
}

// Compaction of both levels: the compacted copies trace as the originals
// did, after the originals' handles are gone; the top level's copy keeps
// the same bottom levels.
TEST_F(AccelerationStructureTest, CompactedCopiesTraceTheSame) {
    const Inputs in = make_inputs(device);
    auto query = vkrc::QueryPool::create(
        device, {.query_type = VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, .query_count = 1});
    vkrc::AccelerationStructure squares, triangle;
    {
        vkrc_test::OneShotCommands s(queue);
        squares =
            vkrc::build_bottom_level(s.cmd, squares_info(in, VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR));
        triangle = vkrc::build_bottom_level(s.cmd, triangle_info(in));
        s.run(queue);
    }
    const VkDeviceSize squares_size = compacted_size(queue, query, squares);
    vkrc::AccelerationStructure scene;
    {
        vkrc_test::OneShotCommands s(queue);
        barrier_between_levels(s.cmd);
        auto small = vkrc::compact(s.cmd, squares, squares_size);
        EXPECT_EQ(small.size(), squares_size);
        EXPECT_LE(small.size(), squares.size());
        barrier_between_levels(s.cmd);
        auto info = scene_info(small, triangle);
        info.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR;
        scene = vkrc::build_top_level(s.cmd, info);
        s.run(queue);
    }
    squares.reset();
    expect_hits(trace(scene), expected_scene);
    const VkDeviceSize scene_size = compacted_size(queue, query, scene);
    vkrc::AccelerationStructure small_scene;
    {
        vkrc_test::OneShotCommands s(queue);
        barrier_between_levels(s.cmd);
        small_scene = vkrc::compact(s.cmd, scene, scene_size);
        s.run(queue);
    }
    EXPECT_EQ(small_scene.bottom_levels().size(), 5u);
    scene.reset();
    expect_hits(trace(small_scene), expected_scene);
    vkrc_test::OneShotCommands s(queue);
    EXPECT_NE(usage_error_of([&] { vkrc::compact(s.cmd, triangle, 256); }).find("not built with ALLOW_COMPACTION"),
              std::string::npos);
    s.run(queue);
}

// Writing a top level into a set keeps it alive through the set, like any descriptor reference.
TEST_F(AccelerationStructureTest, DescriptorWriteKeepsTheStructureAlive) {
    const Inputs in = make_inputs(device);
    auto scene = build_scene(in);
    const std::uint32_t before = scene.use_count();
    auto set = pool.allocate(set_layout);
    set.write_acceleration_structure(0, scene);
    EXPECT_EQ(scene.use_count(), before + 1);
    const VkAccelerationStructureKHR raw = scene.vk();
    set.write_acceleration_structures(0, std::span(&raw, 1));
    EXPECT_EQ(scene.use_count(), before + 1) << "the raw write replaced the wrapper's reference";
    // Through an update template, whose entry the set reads the structure out of.
    auto update = vkrc::DescriptorUpdateTemplate::create(
        device, {.entries = {{0, 0, 1, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 0, sizeof(raw)}},
                 .descriptor_set_layout = set_layout});
    auto other = pool.allocate(set_layout);
    other.update_with_template(update, &raw);
    EXPECT_EQ(scene.use_count(), before + 2);
    set.reset();
    other.reset();
    EXPECT_EQ(scene.use_count(), before);
}

TEST_F(AccelerationStructureTest, BadGeometryIsRefused) {
    const Inputs in = make_inputs(device);
    vkrc_test::OneShotCommands s(queue);
    EXPECT_NE(usage_error_of([&] { vkrc::build_bottom_level(s.cmd, {}); }).find("geometries and aabbs are both empty"),
              std::string::npos);
    auto plain = vkrc::Buffer::create(device, {.size = 64, .usage = VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT});
    vkrc::BottomLevelBuildInfo info = triangle_info(in);
    info.geometries[0].vertex_buffer = plain;
    EXPECT_NE(usage_error_of([&] { vkrc::build_bottom_level(s.cmd, info); })
                  .find("geometries[0].vertex_buffer lacks SHADER_DEVICE_ADDRESS or "
                        "ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY usage"),
              std::string::npos);
    info = triangle_info(in);
    info.geometries[0].max_vertex = 3;  // 4 vertices, the buffer holds 3
    EXPECT_NE(usage_error_of([&] { vkrc::build_bottom_level(s.cmd, info); }).find("the vertex_buffer has 36"),
              std::string::npos);
    info = squares_info(in);
    info.geometries[1].triangle_count = 3;  // 18 bytes of 16-bit indices, the buffer has 16
    EXPECT_NE(usage_error_of([&] { vkrc::build_bottom_level(s.cmd, info); }).find("geometries[1]: 3 triangles"),
              std::string::npos);
    EXPECT_NE(usage_error_of([&] { vkrc::build_top_level(s.cmd, {}); }).find("instances is empty"), std::string::npos);
    s.run(queue);
}

TEST_F(AccelerationStructureTest, MisusedStructuresAreRefused) {
    const Inputs in = make_inputs(device);
    vkrc::AccelerationStructure squares;
    auto scene = build_scene(in, &squares);
    vkrc_test::OneShotCommands s(queue);
    EXPECT_NE(usage_error_of([&] {
                  vkrc::update_bottom_level(s.cmd, squares, squares_info(in));
              }).find("was not built with ALLOW_UPDATE"),
              std::string::npos);
    vkrc::TopLevelBuildInfo info;
    info.instances = {{.bottom_level = scene}};
    EXPECT_NE(usage_error_of([&] {
                  vkrc::build_top_level(s.cmd, info);
              }).find("instances[0].bottom_level is not a bottom-level structure"),
              std::string::npos);
    info.instances = {{.bottom_level = squares, .custom_index = 1u << 24}};
    EXPECT_NE(usage_error_of([&] { vkrc::build_top_level(s.cmd, info); }).find("exceeds 24 bits"), std::string::npos);
    EXPECT_NE(usage_error_of([&] {
                  vkrc::rebuild_top_level(s.cmd, squares, scene_info(squares, squares));
              }).find("the structure is not a top level"),
              std::string::npos);
    auto set = pool.allocate(set_layout);
    EXPECT_NE(usage_error_of([&] { set.write_acceleration_structure(0, squares); }).find("is a bottom level"),
              std::string::npos);
    s.run(queue);
}

// Devices without what acceleration structures need: the builds say what is missing.
using AccelerationStructureRefusal = VulkanTest;

// The extension enabled without its accelerationStructure feature: refused, naming the feature.
TEST_F(AccelerationStructureRefusal, WithoutTheFeatureBuildsAreRefused) {
    if (!physical_device.features().acceleration_structure.accelerationStructure)
        GTEST_SKIP() << "the device lacks accelerationStructure";
    vkrc::DeviceCreateInfo info;
    info.enabled_extension_names = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                                    VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};
    info.vulkan12_features.bufferDeviceAddress = VK_TRUE;
    device = vkrc::Device::create(physical_device, info);
    queue = device.default_queue();
    vkrc_test::OneShotCommands s(queue);
    const std::string message = usage_error_of([&] { vkrc::build_top_level(s.cmd, {}); });
    EXPECT_NE(message.find("vkrc::build_top_level: acceleration structures need the accelerationStructure feature "
                           "enabled"),
              std::string::npos)
        << message;
    s.run(queue);
}

// select() reads the extensions' features and names a missing one.
TEST_F(AccelerationStructureRefusal, RequirementsNameTheMissingFeature) {
    vkrc::DeviceRequirements wanted = vkrc_test::test_device_requirements();
    wanted.required_features.acceleration_structure.accelerationStructureHostCommands = VK_TRUE;
    vkrc_test::expect_requirement_named(
        physical_device, wanted, physical_device.features().acceleration_structure.accelerationStructureHostCommands,
        "lacks feature accelerationStructureHostCommands (VK_KHR_acceleration_structure)");
}

// The fixture's plain device, made without VK_KHR_acceleration_structure.
TEST_F(AccelerationStructureRefusal, WithoutTheExtensionBuildsAreRefused) {
    vkrc_test::OneShotCommands s(queue);
    const std::string message = usage_error_of([&] { vkrc::build_bottom_level(s.cmd, {}); });
    EXPECT_NE(message.find("vkrc::build_bottom_level: acceleration structures need VK_KHR_acceleration_structure "
                           "enabled on the device"),
              std::string::npos)
        << message;
    s.run(queue);
}

}  // namespace
