// examples/raytrace's Vulkan-free headers: the meshlet builder (every triangle exactly once, in
// index order, the limits kept) and the image metrics (PSNR and the counts on known images).
#include "raytrace/image_metrics.hpp"
#include "raytrace/meshlets.hpp"
#include "raytrace/scene.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace {

using raytrace::MeshletLimits;
using raytrace::Meshlets;

// Every meshlet within limits, its vertices distinct, and its triangles, read back through its
// vertices, are indices (plus base_vertex) in order from the first index on.
::testing::AssertionResult rebuilds(const Meshlets& m, std::span<const std::uint16_t> indices,
                                    std::uint32_t base_vertex, MeshletLimits limits) {
    std::vector<std::uint32_t> rebuilt;
    for (std::size_t i = 0; i < m.meshlets.size(); ++i) {
        const auto& meshlet = m.meshlets[i];
        if (meshlet.vertex_count > limits.max_vertices || meshlet.triangle_count > limits.max_triangles ||
            meshlet.triangle_count == 0)
            return ::testing::AssertionFailure() << "meshlet " << i << " has " << meshlet.vertex_count
                                                 << " vertices and " << meshlet.triangle_count << " triangles";
        const auto first = m.vertices.begin() + meshlet.vertex_offset;
        std::vector<std::uint32_t> vertices(first, first + meshlet.vertex_count);
        std::sort(vertices.begin(), vertices.end());
        if (std::adjacent_find(vertices.begin(), vertices.end()) != vertices.end())
            return ::testing::AssertionFailure() << "meshlet " << i << " lists a vertex twice";
        for (std::uint32_t t = 0; t < meshlet.triangle_count; ++t)
            for (int c = 0; c < 3; ++c) {
                const std::uint32_t corner = raytrace::triangle_corner(m.triangles[meshlet.triangle_offset + t], c);
                if (corner >= meshlet.vertex_count)
                    return ::testing::AssertionFailure() << "meshlet " << i << " triangle " << t << " uses corner "
                                                         << corner << " of " << meshlet.vertex_count;
                rebuilt.push_back(m.vertices[meshlet.vertex_offset + corner]);
            }
    }
    std::vector<std::uint32_t> expected;
    for (auto v : indices) expected.push_back(base_vertex + v);
    if (rebuilt != expected)
        return ::testing::AssertionFailure() << "the meshlets give " << rebuilt.size() << " indices, not the "
                                             << expected.size() << " given in order";
    return ::testing::AssertionSuccess();
}

TEST(RaytraceMeshlets, EveryTriangleOfEachTeapotMeshExactlyOnceInOrderWithinTheLimits) {
    const auto scene = raytrace::make_scene();
    const auto& g = scene.geometry;
    Meshlets all;
    for (const auto& mesh : g.meshes) {
        const auto indices = std::span(g.indices).subspan(mesh.first_index, mesh.index_count);
        Meshlets one;
        const auto count = raytrace::append_meshlets(indices, one, std::uint32_t(mesh.vertex_offset));
        EXPECT_EQ(count, one.meshlets.size());
        EXPECT_TRUE(rebuilds(one, indices, std::uint32_t(mesh.vertex_offset), {}));
        // Greedy: a meshlet ends only where the next triangle would break a limit, so the number
        // of meshlets is at least the triangle count over the triangle limit, and each but the
        // last is full in one of the two.
        EXPECT_GE(count, (mesh.index_count / 3 + 123) / 124);
        for (std::size_t i = 0; i + 1 < one.meshlets.size(); ++i)
            EXPECT_TRUE(one.meshlets[i].triangle_count == 124 || one.meshlets[i].vertex_count > 64 - 3) << i;
        raytrace::append_meshlets(indices, all, std::uint32_t(mesh.vertex_offset));
    }
    // Appended to the same arrays, each mesh's meshlets are the ones made alone, offset.
    std::size_t meshlets = 0;
    for (const auto& mesh : g.meshes) {
        Meshlets one;
        const auto count = raytrace::append_meshlets(std::span(g.indices).subspan(mesh.first_index, mesh.index_count),
                                                     one, std::uint32_t(mesh.vertex_offset));
        for (std::uint32_t i = 0; i < count; ++i) {
            const auto& a = all.meshlets[meshlets + i];
            EXPECT_EQ(a.vertex_count, one.meshlets[i].vertex_count);
            EXPECT_EQ(a.triangle_count, one.meshlets[i].triangle_count);
            EXPECT_TRUE(std::equal(one.vertices.begin() + one.meshlets[i].vertex_offset,
                                   one.vertices.begin() + one.meshlets[i].vertex_offset + a.vertex_count,
                                   all.vertices.begin() + a.vertex_offset));
        }
        meshlets += count;
    }
    EXPECT_EQ(meshlets, all.meshlets.size());
}

TEST(RaytraceMeshlets, LimitsCutWhereTheNextTriangleWouldBreakThem) {
    // A strip of 10 triangles over vertices 0..11: triangle t uses t, t + 1, t + 2.
    std::vector<std::uint16_t> strip;
    for (std::uint16_t t = 0; t < 10; ++t) strip.insert(strip.end(), {t, std::uint16_t(t + 1), std::uint16_t(t + 2)});
    Meshlets by_vertices;  // 5 vertices: three triangles, then a new one
    EXPECT_EQ(raytrace::append_meshlets(std::span<const std::uint16_t>(strip), by_vertices, 0, {5, 100}), 4u);
    EXPECT_TRUE(rebuilds(by_vertices, strip, 0, {5, 100}));
    EXPECT_EQ(by_vertices.meshlets[0].vertex_count, 5u);
    EXPECT_EQ(by_vertices.meshlets[0].triangle_count, 3u);
    EXPECT_EQ(by_vertices.meshlets[3].triangle_count, 1u);  // the tenth
    Meshlets by_triangles;
    EXPECT_EQ(raytrace::append_meshlets(std::span<const std::uint16_t>(strip), by_triangles, 7, {64, 4}), 3u);
    EXPECT_TRUE(rebuilds(by_triangles, strip, 7, {64, 4}));
    EXPECT_EQ(by_triangles.meshlets[2].triangle_count, 2u);
    // A triangle with a repeated corner (a collapsed edge) adds its vertex once.
    const std::vector<std::uint16_t> degenerate = {0, 1, 2, 3, 3, 4};
    Meshlets d;
    EXPECT_EQ(raytrace::append_meshlets(std::span<const std::uint16_t>(degenerate), d, 0, {5, 10}), 1u);
    EXPECT_EQ(d.meshlets[0].vertex_count, 5u);
    EXPECT_TRUE(rebuilds(d, degenerate, 0, {5, 10}));
}

TEST(RaytraceMeshlets, RefusesLimitsItCannotKeep) {
    const std::vector<std::uint16_t> one = {0, 1, 2};
    Meshlets m;
    EXPECT_THROW(raytrace::append_meshlets(std::span<const std::uint16_t>(one), m, 0, {257, 10}),
                 std::invalid_argument);
    EXPECT_THROW(raytrace::append_meshlets(std::span<const std::uint16_t>(one), m, 0, {2, 10}), std::invalid_argument);
    EXPECT_THROW(raytrace::append_meshlets(std::span<const std::uint16_t>(one), m, 0, {64, 0}), std::invalid_argument);
    const std::vector<std::uint16_t> partial = {0, 1};
    try {
        raytrace::append_meshlets(std::span<const std::uint16_t>(partial), m, 0);
        ADD_FAILURE() << "2 indices accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_STREQ(e.what(), "raytrace::append_meshlets: 2 indices, not a multiple of 3");
    }
    EXPECT_TRUE(m.meshlets.empty());
}

// An image of pixels, every pixel rgb (alpha 255).
std::vector<std::uint8_t> image(std::size_t pixels, std::array<std::uint8_t, 3> rgb) {
    std::vector<std::uint8_t> out;
    for (std::size_t p = 0; p < pixels; ++p) out.insert(out.end(), {rgb[0], rgb[1], rgb[2], 255});
    return out;
}

TEST(RaytraceImageMetrics, PsnrOfKnownDifferences) {
    const auto grey = image(4, {100, 100, 100});
    const auto same = raytrace::compare_images(grey, grey);
    EXPECT_EQ(same.differing_pixels, 0u);
    EXPECT_EQ(same.max_channel_difference, 0);
    EXPECT_TRUE(std::isinf(same.psnr_db) && same.psnr_db > 0);
    // Every value off by 1: MSE 1, PSNR 20 log10(255) = 48.1308 dB.
    const auto one_off = raytrace::compare_images(grey, image(4, {101, 99, 101}));
    EXPECT_EQ(one_off.differing_pixels, 4u);
    EXPECT_EQ(one_off.max_channel_difference, 1);
    EXPECT_NEAR(one_off.psnr_db, 48.1308, 1e-4);
    // Black against white: MSE 255^2, 0 dB.
    EXPECT_NEAR(raytrace::compare_images(image(2, {0, 0, 0}), image(2, {255, 255, 255})).psnr_db, 0.0, 1e-12);
    // One value of twelve off by 6: MSE 36 / 12 = 3, PSNR 10 log10(65025 / 3) = 43.3596 dB.
    auto one_value = grey;
    one_value[4 * 2 + 1] = 94;
    const auto d = raytrace::compare_images(grey, one_value);
    EXPECT_EQ(d.differing_pixels, 1u);
    EXPECT_EQ(d.max_channel_difference, 6);
    EXPECT_DOUBLE_EQ(d.mean_squared_error, 3.0);
    EXPECT_NEAR(d.psnr_db, 43.3596, 1e-4);
    // One pixel of four: 25%.
    EXPECT_TRUE(raytrace::within(d, {25.0, 6, 43.0}));
    EXPECT_FALSE(raytrace::within(d, {24.9, 6, 43.0}));
    EXPECT_FALSE(raytrace::within(d, {25.0, 5, 43.0}));
    EXPECT_FALSE(raytrace::within(d, {25.0, 6, 43.4}));
    // The default tolerance takes equal images only.
    EXPECT_TRUE(raytrace::within(same, {}));
    EXPECT_FALSE(raytrace::within(d, {}));
}

TEST(RaytraceImageMetrics, AlphaIsNotComparedAndSizesMustAgree) {
    auto a = image(3, {10, 20, 30}), b = a;
    b[3] = 0;
    EXPECT_EQ(raytrace::compare_images(a, b).differing_pixels, 0u);
    b.pop_back();
    EXPECT_THROW(raytrace::compare_images(a, b), std::invalid_argument);
}

}  // namespace
