// The teapot benchmark's scene, shared by every variant and free of Vulkan:
// Newell's Bezier patches, their tessellation into an indexed mesh, the
// mesh's error against the exact surface, and the animation and camera math.
#pragma once

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string_view>
#include <vector>

namespace teapot {

// A bicubic Bezier patch: control point (i, j) is p[i * 4 + j]; i runs along
// u, j along v.
struct Patch {
    std::array<glm::dvec3, 16> p;
};

// Parses the patch file format: the patch count, one line of 16 one-based
// control point indices per patch, the point count, one "x,y,z" line per
// point. Commas and blanks both separate numbers. Throws std::runtime_error
// naming the line on malformed input or an index out of range.
std::vector<Patch> parse_patches(std::string_view text);

// The copy of Newell's teapot shipped with the benchmark (newell_teapot.txt,
// embedded at build time) and its 32 parsed patches, z up.
std::string_view newell_teapot_text();
const std::vector<Patch>& newell_teapot();

glm::dvec3 evaluate(const Patch& patch, double u, double v);

// Position, partial derivatives and the outward unit normal at (u, v).
// Where one tangent vanishes (the lid tip and the bottom centre, whose
// patches collapse a whole edge to a point) the normal is the limit from
// inside the patch, taken analytically from the mixed second derivative.
struct SurfacePoint {
    glm::dvec3 position;
    glm::dvec3 du;
    glm::dvec3 dv;
    glm::dvec3 normal;
};
SurfacePoint evaluate_point(const Patch& patch, double u, double v);

// An indexed triangle mesh of the patches: n x n quads per patch, two
// triangles per quad (degenerate ones at collapsed edges included, so the
// count is always 2 n^2 per patch), vertices welded across patch seams.
struct Mesh {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;
    std::vector<std::uint16_t> indices;
    // Where each triangle came from, for measuring it against the surface.
    struct TriangleSource {
        std::uint32_t patch;
        std::array<glm::dvec2, 3> uv;
    };
    std::vector<TriangleSource> triangle_sources;

    std::size_t triangle_count() const { return indices.size() / 3; }
};

// Vertices closer than this (in model units, the teapot is about 6 wide) are
// one vertex after welding.
inline constexpr double weld_tolerance = 1e-6;

// Throws std::invalid_argument for quads_per_edge < 1 and std::length_error
// when the welded mesh needs more than 65536 vertices (16-bit indices).
Mesh tessellate(std::span<const Patch> patches, int quads_per_edge);

// Distance between the mesh and the exact surface, in model units: each
// triangle is sampled on a barycentric grid with samples_per_edge steps per
// side, and every sample is compared, in double, with the surface point at
// the same (linearly interpolated) patch parameter.
struct GeometricError {
    double max = 0;
    double rms = 0;
    std::size_t samples = 0;
};
GeometricError geometric_error(std::span<const Patch> patches, const Mesh& mesh, int samples_per_edge = 8);

// Per-teapot draw data, the push constant block of shaders/teapot.vert.
struct PushConstants {
    glm::mat4 world;
    glm::vec4 colour;
};
static_assert(sizeof(PushConstants) == 80, "push constant block is mat4 + vec4");

// The uniform block (set 0, binding 0) of shaders/teapot.vert.
struct CameraUniforms {
    glm::mat4 view;
    glm::mat4 proj;
};
static_assert(sizeof(CameraUniforms) == 128);

// Every harmonic of the animation has an angular frequency that is a whole
// multiple of 1/2 rad/s, so the whole animation repeats after 4 pi seconds.
// Time is wrapped by this period in double before any angle is formed, so
// t = 1e7 s gives the same, orthonormal, rotations as a small t.
inline constexpr double animation_period = 4.0 * 3.14159265358979323846;
double wrap_time(double t);

// Teapot index's world matrix (uniform scale, spin about the vertical axis,
// vertical bob with sin(t) for even and -sin(t) for odd indices, placement on
// a square grid of count teapots) and colour at time t.
PushConstants teapot_draw(int index, int count, double t);
void animate(int count, double t, std::span<PushConstants> out);

// The rotation part of teapot_draw's world matrix (tests check it).
glm::dmat3 teapot_rotation(int index, double t);

// Right-handed view looking at the grid of count teapots from the front and
// slightly above; fits the grid into the view whatever the count.
glm::mat4 view_matrix(int count);

// Perspective projection for Vulkan clip space: y down, depth 0 at near and 1
// at far. fov_short is the field of view across the shorter side of the
// viewport, so extreme aspect ratios stay finite. Computed in double. Throws
// std::invalid_argument for a non-finite or non-positive aspect, fov outside
// (0, pi), or not 0 < near < far.
glm::mat4 projection_matrix(double fov_short, double aspect, double near_plane, double far_plane);

// The benchmark's camera for count teapots in a width x height image.
CameraUniforms camera(int count, std::uint32_t width, std::uint32_t height);
// The same camera swaying about the vertical axis with time (a few degrees,
// period animation_period): what the benchmark writes every frame, so a
// uniform stage that stopped writing shows in the image check.
CameraUniforms camera(int count, std::uint32_t width, std::uint32_t height, double t);

}  // namespace teapot
