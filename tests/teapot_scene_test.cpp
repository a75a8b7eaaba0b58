// The teapot benchmark's scene: patch data, tessellation, error measure and
// the numerical hard cases of issue 6 (degenerate normals, rotations at large
// t, projections at extreme aspects and depth ranges).
#include "harness/stats.hpp"
#include "scene/teapot_scene.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>
#include <vector>

namespace {

constexpr double pi = 3.14159265358979323846;

bool finite(const glm::mat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

struct EdgeCounts {
    std::size_t boundary = 0;        // used by one triangle
    std::size_t shared = 0;          // used by two, in opposite directions
    std::size_t same_direction = 0;  // used by two the same way: flipped triangle
    std::size_t over_shared = 0;     // used by more than two
};

// Edge use of the non-degenerate triangles (those at collapsed patch edges
// have two equal indices after welding and are skipped).
EdgeCounts count_edges(const teapot::Mesh& mesh) {
    std::map<std::pair<unsigned, unsigned>, std::pair<int, int>> uses;  // (forward, backward)
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        unsigned v[3] = {mesh.indices[3 * t], mesh.indices[3 * t + 1], mesh.indices[3 * t + 2]};
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) continue;
        for (int k = 0; k < 3; ++k) {
            unsigned a = v[k], b = v[(k + 1) % 3];
            if (a < b) ++uses[{a, b}].first;
            else ++uses[{b, a}].second;
        }
    }
    EdgeCounts counts;
    for (const auto& [edge, use] : uses) {
        int total = use.first + use.second;
        if (total == 1) ++counts.boundary;
        else if (total == 2 && use.first == 1) ++counts.shared;
        else if (total == 2) ++counts.same_direction;
        else ++counts.over_shared;
    }
    return counts;
}

}  // namespace

TEST(TeapotPatches, ShippedFileHas32PatchesOf306Points) {
    const auto& patches = teapot::newell_teapot();
    ASSERT_EQ(patches.size(), 32u);
    // First point of the first patch and the shared lid tip (point 204).
    EXPECT_EQ(patches[0].p[0], glm::dvec3(1.4, 0.0, 2.4));
    EXPECT_EQ(patches[20].p[0], patches[21].p[3]);
}

TEST(TeapotPatches, ParserAcceptsBlanksAndRejectsBadInput) {
    auto one = teapot::parse_patches("1\n1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 2\n2\n0 0 0\n1,2,3\n");
    ASSERT_EQ(one.size(), 1u);
    EXPECT_EQ(one[0].p[15], glm::dvec3(1, 2, 3));
    EXPECT_THROW(teapot::parse_patches("1\n1,2,3\n"), std::runtime_error);  // short line
    EXPECT_THROW(teapot::parse_patches("1\n1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,3\n2\n0,0,0\n1,1,1\n"),
                 std::runtime_error);  // index 3 of 2
    EXPECT_THROW(teapot::parse_patches("1\n1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1\n1\n0,x,0\n"), std::runtime_error);
    EXPECT_THROW(teapot::parse_patches("1\n1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1\n2\n0,0,0\n"), std::runtime_error);
}

TEST(TeapotMesh, FourByFourHas1024TrianglesAndAbout530Vertices) {
    teapot::Mesh mesh = teapot::tessellate(teapot::newell_teapot(), 4);
    EXPECT_EQ(mesh.triangle_count(), 1024u);
    EXPECT_EQ(mesh.indices.size(), 3072u);
    EXPECT_EQ(mesh.triangle_sources.size(), 1024u);
    // 32 * 25 = 800 samples before welding; seams and collapsed edges merge.
    EXPECT_GE(mesh.positions.size(), 500u);
    EXPECT_LE(mesh.positions.size(), 560u);
    EXPECT_EQ(mesh.normals.size(), mesh.positions.size());
    for (auto index : mesh.indices) EXPECT_LT(index, mesh.positions.size());
    for (const auto& n : mesh.normals) EXPECT_NEAR(glm::length(n), 1.0f, 1e-5f);
}

TEST(TeapotMesh, SeamsAreWeldedAndOrientedConsistently) {
    EdgeCounts at4 = count_edges(teapot::tessellate(teapot::newell_teapot(), 4));
    EdgeCounts at8 = count_edges(teapot::tessellate(teapot::newell_teapot(), 8));
    // A manifold, consistently wound surface: no edge is used twice the same
    // way or more than twice.
    EXPECT_EQ(at4.same_direction, 0u);
    EXPECT_EQ(at4.over_shared, 0u);
    EXPECT_EQ(at8.same_direction, 0u);
    EXPECT_EQ(at8.over_shared, 0u);
    // The open boundaries (spout mouth, handle and spout ends, lid and body
    // rims) are a fixed set of patch edges, so their edge count doubles with
    // the tessellation; a seam that failed to weld would add boundary edges
    // and break the proportion, and they are a small part of all edges.
    EXPECT_GT(at4.boundary, 0u);
    EXPECT_EQ(at8.boundary, 2 * at4.boundary);
    EXPECT_LT(at4.boundary * 10, at4.shared);
}

TEST(TeapotMesh, WindingMatchesNormals) {
    teapot::Mesh mesh = teapot::tessellate(teapot::newell_teapot(), 8);
    std::size_t agree = 0, checked = 0;
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        glm::vec3 a = mesh.positions[mesh.indices[3 * t]], b = mesh.positions[mesh.indices[3 * t + 1]],
                  c = mesh.positions[mesh.indices[3 * t + 2]];
        glm::vec3 face = glm::cross(b - a, c - a);
        if (glm::length(face) < 1e-6f) continue;
        glm::vec3 n = mesh.normals[mesh.indices[3 * t]] + mesh.normals[mesh.indices[3 * t + 1]] +
                      mesh.normals[mesh.indices[3 * t + 2]];
        ++checked;
        if (glm::dot(face, n) > 0) ++agree;
    }
    EXPECT_EQ(agree, checked);
}

TEST(TeapotMesh, SixteenBitIndicesHoldTheFinestLevel) {
    teapot::Mesh mesh = teapot::tessellate(teapot::newell_teapot(), 32);
    EXPECT_EQ(mesh.triangle_count(), 32u * 2 * 32 * 32);
    EXPECT_LE(mesh.positions.size(), 65536u);
    EXPECT_THROW(teapot::tessellate(teapot::newell_teapot(), 0), std::invalid_argument);
    // 48 x 48 quads per patch need about 74k vertices: refused, not wrapped.
    EXPECT_THROW(teapot::tessellate(teapot::newell_teapot(), 48), std::length_error);
}

TEST(TeapotNormals, DegeneratePointsAreFiniteUnitAndOutward) {
    const auto& patches = teapot::newell_teapot();
    // Lid tip: patches 21-24 collapse their u = 0 edge to the top point.
    // Bottom centre: patches 29-32 collapse their u = 0 edge to the origin.
    struct Case {
        int first_patch;
        glm::dvec3 outward;
    };
    for (Case c : {Case{20, {0, 0, 1}}, Case{28, {0, 0, -1}}}) {
        for (int p = c.first_patch; p < c.first_patch + 4; ++p)
            for (double v : {0.0, 0.25, 0.5, 1.0}) {
                teapot::SurfacePoint s = teapot::evaluate_point(patches[p], 0.0, v);
                ASSERT_LT(glm::length(s.dv), 1e-12) << "patch " << p << " is not degenerate here";
                ASSERT_TRUE(std::isfinite(s.normal.x) && std::isfinite(s.normal.y) && std::isfinite(s.normal.z));
                EXPECT_NEAR(glm::length(s.normal), 1.0, 1e-12);
                EXPECT_GT(glm::dot(s.normal, c.outward), 0.999999) << "patch " << p << " v " << v;
                // The limit agrees with the normal just inside the patch.
                teapot::SurfacePoint inside = teapot::evaluate_point(patches[p], 1e-4, v);
                EXPECT_GT(glm::dot(s.normal, inside.normal), 0.999);
            }
    }
    // The welded mesh has one vertex at each of the two points, with the same normal.
    teapot::Mesh mesh = teapot::tessellate(patches, 4);
    int tips = 0;
    for (std::size_t k = 0; k < mesh.positions.size(); ++k) {
        if (glm::length(glm::dvec3(mesh.positions[k]) - patches[20].p[0]) < 1e-6) {
            ++tips;
            EXPECT_GT(mesh.normals[k].z, 0.99999f);
        }
        if (glm::length(glm::dvec3(mesh.positions[k]) - patches[28].p[0]) < 1e-6) {
            ++tips;
            EXPECT_LT(mesh.normals[k].z, -0.99999f);
        }
    }
    EXPECT_EQ(tips, 2);
}

TEST(TeapotError, DecreasesWithTessellationAndIsZeroAtVertices) {
    const auto& patches = teapot::newell_teapot();
    double previous_max = 1e9, previous_rms = 1e9;
    for (int n : {2, 4, 8, 16, 32}) {
        teapot::GeometricError e = teapot::geometric_error(patches, teapot::tessellate(patches, n), 4);
        EXPECT_LT(e.max, previous_max) << n;
        EXPECT_LT(e.rms, previous_rms) << n;
        EXPECT_LE(e.rms, e.max);
        previous_max = e.max;
        previous_rms = e.rms;
    }
    // Chordal error of a smooth surface falls about fourfold per halving.
    EXPECT_LT(previous_max, 5e-3);
    // Sampling only the corners measures the float rounding of the vertices.
    teapot::GeometricError corners = teapot::geometric_error(patches, teapot::tessellate(patches, 4), 1);
    EXPECT_LT(corners.max, 1e-6);
}

TEST(TeapotAnimation, RotationsStayOrthonormalAtLargeTimes) {
    for (double t : {0.0, 1.0, 1e4, 1e7}) {
        for (int index : {0, 1, 7, 24}) {
            // What the GPU gets: the float world matrix of the push constants.
            glm::mat4 world = teapot::teapot_draw(index, 25, t).world;
            glm::mat3 r(world);
            glm::mat3 gram = glm::transpose(r) * r;
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    EXPECT_NEAR(gram[i][j], i == j ? 1.0f : 0.0f, 1e-5f) << "t " << t << " teapot " << index;
            EXPECT_NEAR(glm::determinant(r), 1.0f, 1e-5f);
            ASSERT_TRUE(finite(world));
        }
    }
    // Wrapping is exact: t and t + period give the same frame.
    glm::dmat3 a = teapot::teapot_rotation(3, 1e7), b = teapot::teapot_rotation(3, teapot::wrap_time(1e7));
    for (int i = 0; i < 3; ++i) EXPECT_EQ(a[i], b[i]);
    EXPECT_GE(teapot::wrap_time(-1.0), 0.0);
    EXPECT_LT(teapot::wrap_time(1e7), teapot::animation_period);
}

TEST(TeapotAnimation, EvenAndOddTeapotsBobOppositely) {
    double t = 1.0;
    // Rotation about the middle moves the base too; compare the middle.
    auto middle = [](int index, double time) {
        auto d = teapot::teapot_draw(index, 25, time);
        return (d.world * glm::vec4(0, 0, 1.575f, 1)).y;
    };
    EXPECT_NEAR(middle(0, t) - middle(0, 0), std::sin(t), 1e-5);
    EXPECT_NEAR(middle(1, t) - middle(1, 0), -std::sin(t), 1e-5);
}

TEST(TeapotCamera, ExtremeAspectsAndDepthRangesStayFinite) {
    for (double aspect : {1.0 / 4096.0, 4096.0, 1.0, 4.0 / 3.0})
        for (auto [near_plane, far_plane] : {std::pair{1e-3, 1e3}, std::pair{1.0, 1e6}, std::pair{0.5, 100.0}}) {
            glm::mat4 p = teapot::projection_matrix(pi / 4, aspect, near_plane, far_plane);
            ASSERT_TRUE(finite(p)) << aspect << " " << near_plane << " " << far_plane;
            auto depth = [&](double z) {
                glm::dvec4 clip = glm::dmat4(p) * glm::dvec4(0.0, 0.0, -z, 1.0);
                return clip.z / clip.w;
            };
            EXPECT_NEAR(depth(near_plane), 0.0, 1e-6);
            EXPECT_NEAR(depth(far_plane), 1.0, 1e-6);
            // A point on the frustum's corner maps to finite clip coordinates.
            glm::vec4 corner = p * glm::vec4(1e3f, -1e3f, -float(far_plane), 1.0f);
            EXPECT_TRUE(std::isfinite(corner.x) && std::isfinite(corner.y) && std::isfinite(corner.z));
        }
    EXPECT_THROW(teapot::projection_matrix(pi / 4, 0.0, 1.0, 2.0), std::invalid_argument);
    EXPECT_THROW(teapot::projection_matrix(pi / 4, 1.0, 2.0, 2.0), std::invalid_argument);
    EXPECT_THROW(teapot::projection_matrix(pi / 4, std::nan(""), 1.0, 2.0), std::invalid_argument);
    // The benchmark camera keeps every teapot of the grid inside the image.
    for (int count : {25, 250, 2500}) {
        teapot::CameraUniforms cam = teapot::camera(count, 800, 600);
        ASSERT_TRUE(finite(cam.view) && finite(cam.proj));
        for (int index : {0, count - 1}) {
            glm::vec4 clip =
                cam.proj * cam.view * teapot::teapot_draw(index, count, 0.0).world * glm::vec4(0, 0, 1.575f, 1);
            EXPECT_LT(std::abs(clip.x / clip.w), 1.0f) << count;
            EXPECT_LT(std::abs(clip.y / clip.w), 1.0f) << count;
            EXPECT_GT(clip.z / clip.w, 0.0f);
            EXPECT_LT(clip.z / clip.w, 1.0f);
        }
    }
}

TEST(TeapotStats, QuantilesInterpolateBetweenSamples) {
    std::vector<double> samples{4, 1, 3, 2, 5};
    EXPECT_DOUBLE_EQ(teapot::quantile(samples, 0.5), 3.0);
    EXPECT_DOUBLE_EQ(teapot::quantile(samples, 0.0), 1.0);
    EXPECT_DOUBLE_EQ(teapot::quantile(samples, 1.0), 5.0);
    EXPECT_DOUBLE_EQ(teapot::quantile(samples, 0.125), 1.5);
    teapot::Summary s = teapot::summarize(samples);
    EXPECT_DOUBLE_EQ(s.p5, 1.2);
    EXPECT_DOUBLE_EQ(s.p95, 4.8);
    EXPECT_EQ(teapot::quantile({}, 0.5), 0.0);
}

TEST(TeapotStats, BootstrapRatioBracketsTheTrueRatioAndIsReproducible) {
    std::vector<double> reference, slower;
    for (int i = 0; i < 400; ++i) {
        double x = 10.0 + (i * 37 % 101) * 0.05;  // spread 10..15
        reference.push_back(x);
        slower.push_back(1.5 * x);
    }
    teapot::Ratio r = teapot::bootstrap_ratio(slower, reference);
    EXPECT_NEAR(r.ratio, 1.5, 1e-12);
    EXPECT_LT(r.low, 1.5);
    EXPECT_GT(r.high, 1.5);
    EXPECT_GT(r.low, 1.3);
    EXPECT_LT(r.high, 1.7);
    teapot::Ratio again = teapot::bootstrap_ratio(slower, reference);
    EXPECT_EQ(r.low, again.low);
    EXPECT_EQ(r.high, again.high);
    // Identical constant samples: no spread at all.
    std::vector<double> constant(50, 2.0);
    teapot::Ratio flat = teapot::bootstrap_ratio(constant, constant);
    EXPECT_EQ(flat.ratio, 1.0);
    EXPECT_EQ(flat.low, 1.0);
    EXPECT_EQ(flat.high, 1.0);
    EXPECT_EQ(teapot::bootstrap_ratio(constant, {}).ratio, 0.0);
}

// scripts/gen_bench_docs.py's process_bootstrap recomputes bench/teapot's
// intervals from the committed block data, so both must draw the same
// samples. The expected numbers are process_bootstrap's for the same runs
// (unequal lengths, unsorted, values dense enough that the interval moves
// with the draws: the generator, the pick order and the sorting all count).
TEST(TeapotStats, BlockBootstrapIsTheDocsGeneratorsBitForBit) {
    const int sizes[] = {40, 31, 45, 38, 50, 29, 42, 36};
    std::vector<std::vector<double>> runs;
    for (int r = 0; r < 8; ++r) {
        runs.emplace_back();
        for (int i = 0; i < sizes[r]; ++i)
            runs.back().push_back(1.0 + ((i * 7919 + r * 104729) % 1009) * 0.000137 + r * 0.003);
    }
    teapot::Ratio r = teapot::block_bootstrap_ratio(runs);
    EXPECT_EQ(r.ratio, 0x1.1432a8c9b8455p+0);
    EXPECT_EQ(r.low, 0x1.11fa43fe5c91dp+0);  // seed + 1 gives 0x1.11ec3d0a4c8a1p+0: the draws count
    EXPECT_EQ(r.high, 0x1.1667e0b9e99b3p+0);
    // A run without blocks is left out, as the generator leaves out a process without any.
    runs.insert(runs.begin() + 1, std::vector<double>{});
    teapot::Ratio again = teapot::block_bootstrap_ratio(runs);
    EXPECT_EQ(again.ratio, r.ratio);
    EXPECT_EQ(again.low, r.low);
    EXPECT_EQ(again.high, r.high);
    EXPECT_EQ(teapot::block_bootstrap_ratio({{}, {}}).ratio, 0.0);
}
