// Acceleration structures traced ray by ray (shaders/ray_query_rays.comp:
// origin, direction, tmin and tmax given per ray) and compared with a CPU
// reference in double precision, on the hard cases: rays through shared
// edges and shared vertices (watertightness), grazing rays, geometry far
// from the origin, and overlapping triangles at equal or nearly equal t.
// Then the randomized drop order of bottom levels, top levels and the sets
// that hold them while traces through them are held back on the GPU.
#include "support/acceleration_structures.hpp"
#include "support/features.hpp"
#include "support/wrapped_allocator.hpp"

#include "shaders/ray_query_rays.comp.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <random>
#include <span>
#include <string>
#include <tuple>
#include <vector>

namespace {

// ------------------------------------------------------------ the reference

struct Vec {
    double x = 0, y = 0, z = 0;
};
Vec operator-(const Vec& a, const Vec& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec operator+(const Vec& a, const Vec& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec operator*(double s, const Vec& a) { return {s * a.x, s * a.y, s * a.z}; }
double dot(const Vec& a, const Vec& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec cross(const Vec& a, const Vec& b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double length(const Vec& a) { return std::sqrt(dot(a, a)); }
double max_abs(const Vec& a) { return std::max({std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)}); }

// The spacing of floats at magnitude m: what a float coordinate near m is rounded to.
double float_ulp(double m) { return m < 1e-30 ? 0x1p-149 : std::ldexp(1.0, std::ilogb(m) - 23); }

// A ray as the shader reads it (shaders/ray_query_rays.comp's Ray).
struct GpuRay {
    float origin[3];
    float tmin;
    float direction[3];
    float tmax;
};
// What the shader writes per ray (its Hit).
struct GpuHit {
    float t;
    std::uint32_t custom_index;
    std::uint32_t instance;
    std::uint32_t geometry;
    std::uint32_t primitive;
    float u;
    float v;
    std::uint32_t committed;
    std::uint32_t candidates;
    std::uint32_t candidate_ids[8];  // the first 8: instance << 24 | primitive
};
static_assert(sizeof(GpuRay) == 32 && sizeof(GpuHit) == 68);

GpuRay make_ray(const Vec& origin, const Vec& direction, float tmax = 1000.0f) {
    return {{float(origin.x), float(origin.y), float(origin.z)},
            0.0f,
            {float(direction.x), float(direction.y), float(direction.z)},
            tmax};
}
// The ray exactly as the GPU gets it (float values, widened).
Vec origin_of(const GpuRay& r) { return {r.origin[0], r.origin[1], r.origin[2]}; }
Vec direction_of(const GpuRay& r) { return {r.direction[0], r.direction[1], r.direction[2]}; }

// A triangle in world space (exact: float vertices moved by float
// translations, widened to double), and which of the scene's it is.
struct WorldTriangle {
    Vec a, b, c;
    std::uint32_t custom_index, instance, geometry, primitive;
};

// Where a ray meets a triangle's plane, as Woop, Benthin and Wald, "Watertight
// Ray/Triangle Intersection" (JCGT 2013) decide it: by the signs of three
// edge functions that depend only on the ray and each edge's two vertices,
// so that two triangles sharing an edge see it the same way (no gap, the
// edge counted by both). The paper shears the ray onto its largest axis kz
// and takes 2-D cross products; here each is the scalar triple product
// d . ((V1 - o) x (V2 - o)), the paper's value times -|d_kz| (one factor
// for all three, so the same test), in double: exact for the small dyadic
// coordinates of the watertightness meshes, so a ray through an edge gives
// exactly 0.
struct PlaneHit {
    bool parallel = true;  // the ray lies in or parallel to the plane (zero area seen from the ray)
    double t = 0;          // in units of the ray's direction, as the shader's t
    double w[3] = {};      // barycentric weights of a, b, c (w[1], w[2]: the shader's u, v)
    double e[3] = {};      // the edge functions (opposite a, b, c)
    // Inside or on the boundary: no edge function of the other sign.
    bool touches() const {
        if (parallel) return false;
        const bool negative = e[0] < 0 || e[1] < 0 || e[2] < 0;
        const bool positive = e[0] > 0 || e[1] > 0 || e[2] > 0;
        return !(negative && positive);
    }
    bool on_boundary() const { return touches() && (e[0] == 0 || e[1] == 0 || e[2] == 0); }
};

PlaneHit plane_hit(const Vec& o, const Vec& d, const WorldTriangle& tri) {
    const Vec a = tri.a - o, b = tri.b - o, c = tri.c - o;
    PlaneHit h;
    h.e[0] = dot(d, cross(b, c));
    h.e[1] = dot(d, cross(c, a));
    h.e[2] = dot(d, cross(a, b));
    const Vec n = cross(tri.b - tri.a, tri.c - tri.a);
    const double det = dot(n, d);  // = e[0] + e[1] + e[2]
    if (det == 0 || (h.e[0] == 0 && h.e[1] == 0 && h.e[2] == 0)) return h;
    h.parallel = false;
    h.t = dot(n, a) / det;
    for (int i = 0; i < 3; ++i) h.w[i] = h.e[i] / det;
    return h;
}

// The smallest altitude of tri: a barycentric weight times it is a distance.
double min_altitude(const WorldTriangle& tri) {
    const double area2 = length(cross(tri.b - tri.a, tri.c - tri.a));
    const double longest = std::max({length(tri.b - tri.a), length(tri.c - tri.b), length(tri.a - tri.c)});
    return area2 / longest;
}

Vec unit_normal(const WorldTriangle& tri) {
    const Vec n = cross(tri.b - tri.a, tri.c - tri.a);
    return (1.0 / length(n)) * n;
}

// ------------------------------------------------------------ the scenes

// One triangle geometry: xyz per vertex, three indices a triangle.
struct Geometry {
    std::vector<float> vertices;
    std::vector<std::uint32_t> indices;
};
// One instance of scene.blases[blas].
struct Placement {
    std::size_t blas;
    VkTransformMatrixKHR transform;
    std::uint32_t custom_index;
};
struct SceneDesc {
    std::vector<std::vector<Geometry>> blases;
    std::vector<Placement> instances;
};

// m applied to v, in double (exact for translations of float vertices).
Vec transformed(const VkTransformMatrixKHR& m, const Vec& v) {
    auto row = [&](int r) {
        return double(m.matrix[r][0]) * v.x + double(m.matrix[r][1]) * v.y + double(m.matrix[r][2]) * v.z +
               double(m.matrix[r][3]);
    };
    return {row(0), row(1), row(2)};
}

std::vector<WorldTriangle> world_triangles(const SceneDesc& scene) {
    std::vector<WorldTriangle> out;
    for (std::uint32_t i = 0; i < scene.instances.size(); ++i) {
        const Placement& p = scene.instances[i];
        const auto& geometries = scene.blases[p.blas];
        for (std::uint32_t g = 0; g < geometries.size(); ++g) {
            const Geometry& geo = geometries[g];
            for (std::uint32_t t = 0; t * 3 < geo.indices.size(); ++t) {
                auto vertex = [&](int k) {
                    const float* v = &geo.vertices[3 * geo.indices[3 * t + k]];
                    return transformed(p.transform, Vec{v[0], v[1], v[2]});
                };
                out.push_back({vertex(0), vertex(1), vertex(2), p.custom_index, i, g, t});
            }
        }
    }
    return out;
}

// A grid of cells x cells squares of side cell from corner (x0, y0, z0),
// two triangles each, the diagonal alternating (so that interior vertices
// join 4 or 8 triangles), all wound counter-clockwise seen from +z; planar,
// z rising by slope_x and slope_y per unit of x and y.
struct GridPlacement {
    double x0 = 0, y0 = 0, z0 = 0;
    double slope_x = 0, slope_y = 0;
};
Geometry grid(int cells, double cell, const GridPlacement& place = {}) {
    Geometry g;
    for (int j = 0; j <= cells; ++j) {
        for (int i = 0; i <= cells; ++i) {
            const double x = i * cell, y = j * cell;
            g.vertices.insert(g.vertices.end(), {float(place.x0 + x), float(place.y0 + y),
                                                 float(place.z0 + place.slope_x * x + place.slope_y * y)});
        }
    }
    const auto at = [&](int i, int j) { return std::uint32_t(j * (cells + 1) + i); };
    for (int j = 0; j < cells; ++j) {
        for (int i = 0; i < cells; ++i) {
            const std::uint32_t v00 = at(i, j), v10 = at(i + 1, j), v11 = at(i + 1, j + 1), v01 = at(i, j + 1);
            if ((i + j) % 2 == 0) {
                g.indices.insert(g.indices.end(), {v00, v10, v11, v00, v11, v01});
            } else {
                g.indices.insert(g.indices.end(), {v00, v10, v01, v10, v11, v01});
            }
        }
    }
    return g;
}

// A closed fan: apex (0, 0, 3) over a ring of eight vertices at z 0, eight
// triangles counter-clockwise seen from +z. Not planar: its shared edges
// are creases.
Geometry pyramid() {
    Geometry g;
    g.vertices = {0, 0, 3, 4, 0, 0, 3, 3, 0, 0, 4, 0, -3, 3, 0, -4, 0, 0, -3, -3, 0, 0, -4, 0, 3, -3, 0};
    for (std::uint32_t i = 0; i < 8; ++i) g.indices.insert(g.indices.end(), {0, 1 + i, 1 + (i + 1) % 8});
    return g;
}

// ------------------------------------------------------------ the checks

// How a test's rays fared against the reference.
struct Tally {
    int rays = 0;
    int ambiguous = 0;  // skipped: within the tolerance of an outer edge
    int wrong = 0;
    double worst_t = 0;     // the largest |t - t_ref| / tolerance seen
    double worst_ulps = 0;  // the largest error along the normal, in float ulps of the scene's magnitude
    void fail(const std::string& what) {
        if (++wrong <= 8) ADD_FAILURE() << what;
    }
};

std::string describe(const GpuRay& r, const GpuHit& h) {
    char text[400];
    std::snprintf(text, sizeof(text),
                  "ray o=(%.9g, %.9g, %.9g) d=(%.9g, %.9g, %.9g): committed %u t %.9g custom %u instance %u geometry "
                  "%u primitive %u uv (%.7g, %.7g), %u candidates:",
                  r.origin[0], r.origin[1], r.origin[2], r.direction[0], r.direction[1], r.direction[2], h.committed,
                  h.t, h.custom_index, h.instance, h.geometry, h.primitive, h.u, h.v, h.candidates);
    std::string out = text;
    for (std::uint32_t k = 0; k < std::min(h.candidates, 8u); ++k) {
        out += " " + std::to_string(h.candidate_ids[k] >> 24) + "/" + std::to_string(h.candidate_ids[k] & 0xFFFFFF);
    }
    return out;
}

bool is(const GpuHit& h, const WorldTriangle& tri) {
    return h.committed == 1 && h.instance == tri.instance && h.geometry == tri.geometry &&
           h.primitive == tri.primitive && h.custom_index == tri.custom_index;
}

// How far (in world units) the GPU's hit may be from the reference's: along
// the triangle's normal, and in its plane.
struct Tolerance {
    double normal;
    double plane;
};

// The committed hit is tri, at t within tol.normal along the normal (over
// |n . d| in t, plus 4 ulps of t) and with barycentrics within tol.plane of
// the reference's (as distances to the edges).
void expect_hit_on(Tally& tally, const GpuRay& r, const GpuHit& h, const WorldTriangle& tri, Tolerance tol,
                   double magnitude) {
    const Vec o = origin_of(r), d = direction_of(r);
    const PlaneHit ref = plane_hit(o, d, tri);
    const double tol_t = tol.normal / std::fabs(dot(unit_normal(tri), d)) + 4 * float_ulp(ref.t);
    const double tol_b = tol.plane / min_altitude(tri) + 4 * 0x1p-24;
    const double dt = std::fabs(double(h.t) - ref.t);
    tally.worst_t = std::max(tally.worst_t, dt / tol_t);
    tally.worst_ulps = std::max(tally.worst_ulps, dt * std::fabs(dot(unit_normal(tri), d)) / float_ulp(magnitude));
    if (dt > tol_t || std::fabs(h.u - ref.w[1]) > tol_b || std::fabs(h.v - ref.w[2]) > tol_b) {
        char text[160];
        std::snprintf(text, sizeof(text), " | expected t %.9g (tolerance %.3g), uv (%.7g, %.7g) (tolerance %.3g)",
                      ref.t, tol_t, ref.w[1], ref.w[2], tol_b);
        tally.fail(describe(r, h) + text);
    }
}

// tri as the shader records a candidate.
std::uint32_t candidate_id(const WorldTriangle& tri) { return tri.instance << 24 | tri.primitive; }

// Whether the driver reports a ray through a shared edge or vertex on every
// triangle there: lavapipe's triangle test (Mesa's lvp_nir_ray_tracing.c,
// lvp_build_intersect_ray_tri) is Woop et al.'s with inclusive edges (a
// hit unless an edge function is negative and another positive) and no
// tie-break, so a shared edge is both triangles'. The spec's watertightness
// rule is a "should" (see below): no gap is required, one hit is recommended.
bool reports_every_touching_triangle(const vkrc::PhysicalDevice& physical) {
    VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDeviceProperties2 properties{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &driver};
    physical.fn().vkGetPhysicalDeviceProperties2(physical.vk(), &properties);
    return driver.driverID == VK_DRIVER_ID_MESA_LLVMPIPE;
}

// The candidates a ray reported are some of the triangles it may hit
// (allowed), each once: at least one (no gap), and one only unless
// every_touching. (These meshes are one geometry each: instance and
// primitive name a triangle.)
bool candidates_within(const GpuHit& h, const std::vector<const WorldTriangle*>& allowed, bool every_touching) {
    const std::size_t most = every_touching ? allowed.size() : 1;
    if (h.candidates < 1 || h.candidates > most || h.candidates > 8) return false;
    std::vector<std::uint32_t> seen(h.candidate_ids, h.candidate_ids + h.candidates);
    std::sort(seen.begin(), seen.end());
    if (std::adjacent_find(seen.begin(), seen.end()) != seen.end()) return false;
    return std::all_of(seen.begin(), seen.end(), [&](std::uint32_t id) {
        return std::any_of(allowed.begin(), allowed.end(),
                           [&](const WorldTriangle* t) { return candidate_id(*t) == id; });
    });
}

// The edges of only one triangle: a mesh's outer boundary.
struct Segment {
    Vec a, b;
};
std::vector<Segment> outer_edges(const std::vector<WorldTriangle>& triangles) {
    using Key = std::array<double, 6>;
    std::vector<std::pair<Key, Segment>> edges;
    for (const auto& tri : triangles) {
        const Vec v[3] = {tri.a, tri.b, tri.c};
        for (int k = 0; k < 3; ++k) {
            Vec p = v[k], q = v[(k + 1) % 3];
            if (std::tie(q.x, q.y, q.z) < std::tie(p.x, p.y, p.z)) std::swap(p, q);
            edges.push_back({{p.x, p.y, p.z, q.x, q.y, q.z}, {p, q}});
        }
    }
    std::sort(edges.begin(), edges.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<Segment> out;
    for (std::size_t i = 0; i < edges.size(); ++i) {
        const bool shared = (i > 0 && edges[i - 1].first == edges[i].first) ||
                            (i + 1 < edges.size() && edges[i + 1].first == edges[i].first);
        if (!shared) out.push_back(edges[i].second);
    }
    return out;
}

double distance(const Vec& p, const Segment& s) {
    const Vec e = s.b - s.a;
    const double f = std::clamp(dot(p - s.a, e) / dot(e, e), 0.0, 1.0);
    return length(p - (s.a + f * e));
}

// A planar mesh: its triangles, its outer edges, and whether the driver
// reports every triangle a ray touches.
struct PlanarMesh {
    const std::vector<WorldTriangle>& triangles;
    const std::vector<Segment>& outer;
    bool every_touching;  // see reports_every_touching_triangle
};

// Checks one ray through a planar mesh against the reference. Where the
// ray meets the plane within tol.plane of the outer edge it may hit or
// miss: ambiguous, counted and skipped. Outside, a miss; inside, one hit
// (see candidates_within) on a triangle whose edges are within tol.plane,
// as expect_hit_on checks it.
void check_planar(Tally& tally, const PlanarMesh& mesh, const GpuRay& r, const GpuHit& h, Tolerance tol,
                  double magnitude) {
    const Vec o = origin_of(r), d = direction_of(r);
    const PlaneHit p = plane_hit(o, d, mesh.triangles[0]);
    const Vec at = o + p.t * d;
    double edge = INFINITY;
    for (const Segment& s : mesh.outer) edge = std::min(edge, distance(at, s));
    std::vector<const WorldTriangle*> allowed;
    bool inside = false;
    for (const auto& tri : mesh.triangles) {
        const PlaneHit q = plane_hit(o, d, tri);
        inside |= q.touches();
        // As distances to the edges, smaller than they are (for the shortest altitude).
        if (std::min({q.w[0], q.w[1], q.w[2]}) * min_altitude(tri) >= -tol.plane) allowed.push_back(&tri);
    }
    if (edge <= tol.plane) {
        ++tally.ambiguous;
        return;
    }
    if (!inside) {
        if (h.committed != 0 || h.candidates != 0) tally.fail("expected a miss: " + describe(r, h));
        return;
    }
    const auto it = std::find_if(allowed.begin(), allowed.end(), [&](const WorldTriangle* t) { return is(h, *t); });
    if (!candidates_within(h, allowed, mesh.every_touching) || it == allowed.end()) {
        tally.fail("expected a hit on one of " + std::to_string(allowed.size()) + " triangles: " + describe(r, h));
        return;
    }
    expect_hit_on(tally, r, h, **it, tol, magnitude);
}

// --------------------------------------------------------------- the fixture

struct Tracer {
    vkrc::DescriptorSetLayout set_layout;
    vkrc::PipelineLayout layout;
    vkrc::ComputePipeline pipeline;
};

struct TraceParams {
    std::uint32_t count;
};

Tracer make_tracer(const vkrc::Device& device) {
    Tracer t;
    t.set_layout = vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{.binding = 0, .descriptor_type = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR},
                              {.binding = 1, .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                              {.binding = 2, .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}}});
    t.layout = vkrc::PipelineLayout::create(
        device, {.set_layouts = {t.set_layout},
                 .push_constant_ranges = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(TraceParams)}}});
    t.pipeline =
        vkrc::ComputePipeline::create(t.layout, vkrc::ShaderModule::create(device, vkrc_shaders::ray_query_rays_comp));
    return t;
}

vkrc::DescriptorPool make_set_pool(const vkrc::Device& device, std::uint32_t sets) {
    return vkrc::DescriptorPool::create(device, {.max_sets = sets,
                                                 .pool_sizes = {{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, sets},
                                                                {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2 * sets}}});
}

vkrc::Buffer ray_buffer(const vkrc::Device& device, const std::vector<GpuRay>& rays) {
    auto b = vkrc::Buffer::create(device, {.size = rays.size() * sizeof(GpuRay),
                                           .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                           .memory = {.usage = vkrc::MemoryUsage::upload}});
    b.allocation().write(0, rays.data(), rays.size());
    return b;
}

vkrc::Buffer hit_buffer(const vkrc::Device& device, std::size_t count) {
    return vkrc::Buffer::create(device, {.size = count * sizeof(GpuHit),
                                         .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                         .memory = {.usage = vkrc::MemoryUsage::readback}});
}

// Records the trace of count rays through set: a barrier from the builds
// before, one to the host after.
void record_trace(const vkrc::CommandBuffer& cmd, const Tracer& tracer, const vkrc::DescriptorSet& set,
                  std::uint32_t count) {
    const auto built =
        vkrc_test::built_to(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_ACCELERATION_STRUCTURE_READ_BIT_KHR);
    cmd.pipeline_barrier(std::span(&built, 1), {}, {});
    cmd.bind_pipeline(tracer.pipeline);
    cmd.bind_descriptor_set(tracer.pipeline, 0, set);
    cmd.push_constants(tracer.layout, VK_SHADER_STAGE_COMPUTE_BIT, TraceParams{count});
    cmd.dispatch((count + 63) / 64);
    const auto to_host = vkrc_test::compute_to_host();
    cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
}

// scene's instances over blases, one per scene.blases entry.
vkrc::TopLevelBuildInfo top_level_info(const SceneDesc& scene, const std::vector<vkrc::AccelerationStructure>& blases,
                                       const vkrc::SharedAllocator& allocator = {}) {
    vkrc::TopLevelBuildInfo top;
    top.allocator = allocator;
    for (const Placement& p : scene.instances) {
        top.instances.push_back(
            {.bottom_level = blases[p.blas], .transform = p.transform, .custom_index = p.custom_index});
    }
    return top;
}

// Records the builds of scene's bottom levels (into blases, one each) and
// then its top level, their memory from allocator.
vkrc::AccelerationStructure record_scene(const vkrc::CommandBuffer& cmd, const SceneDesc& scene,
                                         std::vector<vkrc::AccelerationStructure>& blases,
                                         const vkrc::SharedAllocator& allocator = {}) {
    const vkrc::Device& device = cmd.pool().device();
    blases.resize(scene.blases.size());
    for (std::size_t b = 0; b < scene.blases.size(); ++b) {
        const auto& geometries = scene.blases[b];
        vkrc::BottomLevelBuildInfo info;
        info.allocator = allocator;
        for (const Geometry& g : geometries) {
            // The buffers go with info: dropped while cmd records, they wait for the build.
            info.geometries.push_back(
                {.vertex_buffer = vkrc_test::build_input(device, g.vertices),
                 .max_vertex = std::uint32_t(g.vertices.size() / 3 - 1),
                 .index_buffer = vkrc_test::build_input(device, g.indices),
                 .triangle_count = std::uint32_t(g.indices.size() / 3),
                 .flags = VK_GEOMETRY_OPAQUE_BIT_KHR | VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT_KHR});
        }
        blases[b] = vkrc::build_bottom_level(cmd, info);
    }
    vkrc_test::barrier_between_levels(cmd);
    return vkrc::build_top_level(cmd, top_level_info(scene, blases, allocator));
}

class RayPrecisionTest : public vkrc_test::RayQueryTest {
protected:
    void SetUp() override {
        RayQueryTest::SetUp();
        if (HasFatalFailure() || IsSkipped()) return;
        tracer = make_tracer(device);
        pool = make_set_pool(device, 4);
    }

    vkrc::AccelerationStructure build(const SceneDesc& scene) const {
        vkrc_test::OneShotCommands s(queue);
        std::vector<vkrc::AccelerationStructure> blases;
        auto top = record_scene(s.cmd, scene, blases);
        s.run(queue);
        return top;
    }

    std::vector<GpuHit> trace(const vkrc::AccelerationStructure& scene, const std::vector<GpuRay>& rays) const {
        const auto in = ray_buffer(device, rays);
        const auto out = hit_buffer(device, rays.size());
        auto set = pool.allocate(tracer.set_layout);
        set.write_acceleration_structure(0, scene);
        set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, in);
        set.write_buffer(2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, out);
        vkrc_test::OneShotCommands s(queue);
        record_trace(s.cmd, tracer, set, std::uint32_t(rays.size()));
        s.run(queue);
        std::vector<GpuHit> hits(rays.size());
        out.allocation().read(0, hits.data(), hits.size());
        return hits;
    }

    Tracer tracer;
    vkrc::DescriptorPool pool;
};

// ------------------------------------------------------------ watertightness

// The Vulkan specification, "Ray Traversal" > "Watertightness"
// (chapters/raytraversal.adoc), for triangles with identical transforms
// within one instance: two triangles with two shared vertices, specified in
// the same winding order, have a shared edge; a closed fan is three or more
// triangles around one shared vertex whose edges there are all shared by
// exactly two of them. "Implementations should: not double-hit or miss when
// a ray intersects a shared edge, or a shared vertex of a closed fan." A
// should, not a must. Lavapipe keeps half of it: it never misses, but it
// double-hits (see reports_every_touching_triangle): 2 candidates at most
// edges, up to the whole fan at a vertex (fewer where its float shear
// moves the point off the vertex, or its box test leaves out a box the ray
// only touches). The test requires, everywhere, no miss and no candidate
// but the touching triangles; exactly one candidate on other drivers; and
// a committed (closest) hit on one of the touching triangles, with t and
// barycentrics right.
//
// The targets lie exactly on the shared edges (their midpoints and quarter
// points) and on the interior vertices of a grid (closed fans of 4 and 8
// planar triangles) and of a pyramid (a closed fan of 8 creased triangles),
// all dyadic, so the reference finds every target on two or more triangles'
// boundaries exactly. Each target is traced from several directions, all
// steeper than the surfaces, so each ray crosses them once.
TEST_F(RayPrecisionTest, RaysThroughSharedEdgesAndVerticesNeverMiss) {
    const bool every_touching = reports_every_touching_triangle(physical_device);
    SceneDesc scene;
    scene.blases = {{grid(8, 2.0)}, {pyramid()}};
    scene.instances = {{0, vkrc_test::placed(0, 0, 0), 1}, {1, vkrc_test::placed(30, 30, 0), 2}};
    const auto triangles = world_triangles(scene);

    std::vector<Vec> targets;
    for (int j = 1; j < 8; ++j) {
        for (int i = 1; i < 8; ++i) targets.push_back({2.0 * i, 2.0 * j, 0});  // interior vertices
    }
    // Points along every interior edge: each triangle's edges, kept where
    // the reference finds the point on two triangles (the outer edges have one).
    std::vector<Vec> on_edges;
    for (const auto& tri : triangles) {
        const Vec v[3] = {tri.a, tri.b, tri.c};
        for (int k = 0; k < 3; ++k) {
            for (double f : {0.25, 0.5, 0.75}) on_edges.push_back(v[k] + f * (v[(k + 1) % 3] - v[k]));
        }
    }
    std::sort(on_edges.begin(), on_edges.end(),
              [](const Vec& a, const Vec& b) { return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z); });
    on_edges.erase(std::unique(on_edges.begin(), on_edges.end(),
                               [](const Vec& a, const Vec& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }),
                   on_edges.end());
    targets.insert(targets.end(), on_edges.begin(), on_edges.end());
    targets.push_back({30, 30, 3});  // the pyramid's apex

    const Vec directions[] = {{0, 0, -1}, {1, 2, -8}, {-3, 1, -7}, {2, -2, -5}, {-1, -1, -4}};
    std::vector<GpuRay> rays;
    std::vector<std::vector<const WorldTriangle*>> touching;  // per ray, the triangles the reference finds
    int vertex_rays = 0;
    for (const Vec& p : targets) {
        for (const Vec& d : directions) {
            const GpuRay r = make_ray(p - 2.0 * d, d);
            std::vector<const WorldTriangle*> on;
            bool interior = false;
            for (const auto& tri : triangles) {
                const PlaneHit h = plane_hit(origin_of(r), direction_of(r), tri);
                if (!h.touches()) continue;
                ASSERT_TRUE(h.on_boundary()) << "a target lies on an edge";
                ASSERT_EQ(h.t, 2.0);
                on.push_back(&tri);
                interior |= on.size() >= 2;
            }
            if (!interior) continue;  // an outer edge: the spec promises nothing there
            if (on.size() > 2) ++vertex_rays;
            rays.push_back(r);
            touching.push_back(std::move(on));
        }
    }
    ASSERT_GT(vertex_rays, 0);
    const auto hits = trace(build(scene), rays);
    Tally tally;
    int double_hits = 0, misses = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        ++tally.rays;
        const GpuHit& h = hits[i];
        const auto& on = touching[i];
        if (h.candidates == 0) ++misses;
        if (h.candidates > 1) ++double_hits;
        if (!candidates_within(h, on, every_touching)) {
            tally.fail("candidates: " + describe(rays[i], h) + " | expected " + (every_touching ? "1 or more" : "1") +
                       " of the " + std::to_string(on.size()) + " touching triangles");
            continue;
        }
        const auto it = std::find_if(on.begin(), on.end(), [&](const WorldTriangle* t) { return is(h, *t); });
        if (it == on.end()) {
            tally.fail("committed: " + describe(rays[i], h) + " | not one of the touching triangles");
            continue;
        }
        expect_hit_on(tally, rays[i], h, **it, {4 * float_ulp(32), 8 * float_ulp(32)}, 32);
    }
    std::printf(
        "%d rays through shared edges (%d through shared vertices): %d wrong; %d missed, %d hit more than "
        "one triangle%s; worst |t - t_ref| %.3g of the tolerance\n",
        tally.rays, vertex_rays, tally.wrong, misses, double_hits,
        every_touching ? " (this driver reports every touching triangle)" : "", tally.worst_t);
    EXPECT_EQ(tally.wrong, 0);
}

// ------------------------------------------------------------ grazing rays

// A square of two triangles (a shared diagonal) at z 0, spanning
// [-64, 64]^2, hit at angles from 0.1 down to 1e-5 radians from its plane,
// and rays exactly parallel to it: in the plane (the triangle has zero area
// seen from the ray, and the spec's "Ray Face Culling" culls an
// intersection candidate of zero area unconditionally) or just above and
// below it (no intersection at all): all miss.
//
// Tolerance: an error of delta along the normal moves the hit by
// delta / sin(angle) along the ray. The spec's ray space is a rotation of
// the ray onto -z, so an implementation may make errors of a few float ulps
// of the coordinates (magnitude 80 here) in any direction: 4 ulps along the
// normal (over sin(angle) in t), and the same over sin(angle) in the plane.
// A hit point within that of the square's edge would be ambiguous; the
// targets lie within [-8, 8]^2 or 8 beyond the edges, so none is (the test
// asserts so).
TEST_F(RayPrecisionTest, GrazingRaysAgreeWithTheReference) {
    SceneDesc scene;
    scene.blases = {{grid(1, 128.0, {.x0 = -64, .y0 = -64})}};
    scene.instances = {{0, vkrc_test::placed(0, 0, 0), 4}};
    const auto triangles = world_triangles(scene);
    const auto outer = outer_edges(triangles);
    const PlanarMesh mesh{triangles, outer, reports_every_touching_triangle(physical_device)};
    std::mt19937 rng(31);
    std::uniform_real_distribution<double> uniform(0, 1);
    std::vector<GpuRay> rays;
    for (double a : {0.1, 1e-2, 1e-3, 1e-4, 1e-5}) {
        for (int k = 0; k < 64; ++k) {
            const double phi = 2 * std::numbers::pi * uniform(rng);
            const Vec d{std::cos(a) * std::cos(phi), std::cos(a) * std::sin(phi), -std::sin(a)};
            Vec target{16 * uniform(rng) - 8, 16 * uniform(rng) - 8, 0};
            if (k % 4 == 3) target.x = (k % 8 == 3 ? 1 : -1) * (72 + 8 * uniform(rng));  // beyond an edge
            rays.push_back(make_ray(target - 4.0 * d, d));
        }
    }
    // Exactly parallel: in the plane (across the diagonal and along it), above and below.
    std::vector<GpuRay> parallel;
    for (double z : {0.0, 1e-3, -1e-3, 0x1p-40}) {
        parallel.push_back(make_ray({-80, 3, z}, {1, 0, 0}));
        parallel.push_back(make_ray({5, -80, z}, {0, 1, 0}));
        parallel.push_back(make_ray({-80, -70, z}, {1, 0.875, 0}));
        parallel.push_back(make_ray({-80, -80, z}, {1, 1, 0}));  // along the shared diagonal
    }
    std::vector<GpuRay> all = rays;
    all.insert(all.end(), parallel.begin(), parallel.end());
    const auto hits = trace(build(scene), all);

    Tally tally;
    const double magnitude = 80;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        ++tally.rays;
        const Vec d = direction_of(rays[i]);
        const double sin_a = std::fabs(d.z) / length(d);
        const double normal = 4 * float_ulp(magnitude);
        check_planar(tally, mesh, rays[i], hits[i], {normal, normal / sin_a}, magnitude);
    }
    for (std::size_t i = 0; i < parallel.size(); ++i) {
        const GpuHit& h = hits[rays.size() + i];
        if (h.committed != 0 || h.candidates != 0) tally.fail("parallel ray hit: " + describe(parallel[i], h));
    }
    std::printf(
        "%d grazing rays and %zu parallel ones: %d wrong; worst |t - t_ref| %.3g of the tolerance, %.3g "
        "ulps of %g along the normal\n",
        tally.rays, parallel.size(), tally.wrong, tally.worst_t, tally.worst_ulps, magnitude);
    EXPECT_EQ(tally.wrong, 0);
    EXPECT_EQ(tally.ambiguous, 0) << "a target within the tolerance of the square's edge";
}

// ------------------------------------------------------------ far from the origin

// How the far test places its grid: by its vertex coordinates, by the
// instance's translation, or by a rotation about z and that translation.
enum class FarBy { vertices, translation, rotation };

// A tilted 8 x 8 grid (its plane rising 1/4 per unit of x, falling 1/8 per
// unit of y) placed at (m, m, m) for m = 1e5, 1e6 and 1e7, three ways
// (FarBy), traced by random rays from above it (at most about 55 degrees
// from the normal) aimed at [-2, 10]^2 cells of it.
//
// Tolerance: float coordinates near m are spaced ulp(m) apart (1/128 at
// 1e5, 1/16 at 1e6, 1 at 1e7), and every step of a traversal in float that
// subtracts them (the ray origin from a vertex, the instance's translation
// from the ray origin) may round by half of that. The reference computes
// with the same float inputs, exactly, so the GPU's error is its own:
// allowed 4 ulp(m) along the normal (t's tolerance is that over |n . d|)
// and 4 ulp(m) (1 + tan angle) in the plane. A rotated instance is traced
// through the world-to-object matrix the implementation inverts in float,
// whose translation column (a dot product of three terms of magnitude m)
// may be off by 3 ulp(m) more: 8 ulp(m) there. The grid's cells are
// 256 ulp(m) wide (and its heights multiples of 32 ulp(m)), so the
// geometry itself is exact at every m. A ray meeting the plane within the
// in-plane tolerance of the grid's outer edge may hit or miss: it is
// ambiguous, skipped and counted (the count must stay under 5% of the
// rays); one within it of an interior edge must still hit (watertightness
// holds far away too).
TEST_F(RayPrecisionTest, GeometryFarFromTheOriginAgreesWithinFloatPrecision) {
    const bool every_touching = reports_every_touching_triangle(physical_device);
    std::mt19937 rng(6);
    std::uniform_real_distribution<double> uniform(0, 1);
    const char* names[] = {"by its vertices", "by the instance's translation", "by a rotated instance"};
    for (double m : {1e5, 1e6, 1e7}) {
        for (FarBy by : {FarBy::vertices, FarBy::translation, FarBy::rotation}) {
            const char* name = names[static_cast<int>(by)];
            SCOPED_TRACE("at " + std::to_string(m) + " " + name);
            const auto far = float(m);
            const double cell = 256 * float_ulp(m);
            const int cells = 8;
            // The grid in its own space, and the instance's transform.
            GridPlacement local{.slope_x = 0.25, .slope_y = -0.125};
            VkTransformMatrixKHR transform = vkrc_test::placed(far, far, far);
            if (by == FarBy::vertices) {
                local.x0 = local.y0 = local.z0 = far;
                transform = vkrc_test::placed(0, 0, 0);
            } else if (by == FarBy::rotation) {
                const float c = 0.8f, s = 0.6f;  // about 37 degrees
                transform = {{{c, -s, 0, far}, {s, c, 0, far}, {0, 0, 1, far}}};
            }
            SceneDesc scene;
            scene.blases = {{grid(cells, cell, local)}};
            scene.instances = {{0, transform, 7}};
            const auto triangles = world_triangles(scene);
            const auto outer = outer_edges(triangles);
            const PlanarMesh mesh{triangles, outer, every_touching};
            const double extent = cells * cell;
            std::vector<GpuRay> rays;
            for (int k = 0; k < 1024; ++k) {
                const double x = (1.5 * uniform(rng) - 0.25) * extent, y = (1.5 * uniform(rng) - 0.25) * extent;
                const Vec target = transformed(
                    transform, {local.x0 + x, local.y0 + y, local.z0 + local.slope_x * x + local.slope_y * y});
                const Vec from = target + Vec{(4 * uniform(rng) - 2) * cell, (4 * uniform(rng) - 2) * cell,
                                              (2 + 4 * uniform(rng)) * cell};
                rays.push_back(make_ray(from, target - from));
            }
            const auto hits = trace(build(scene), rays);
            Tally tally;
            const double magnitude = 1.01 * m + 2 * extent;  // the largest coordinate
            const double ulps = by == FarBy::rotation ? 8 : 4;
            for (std::size_t i = 0; i < rays.size(); ++i) {
                ++tally.rays;
                const Vec d = direction_of(rays[i]);
                const double cos_n = std::fabs(dot(unit_normal(triangles[0]), d)) / length(d);
                const double tan_a = std::sqrt(1 - cos_n * cos_n) / cos_n;
                const double normal = ulps * float_ulp(magnitude);
                check_planar(tally, mesh, rays[i], hits[i], {normal, normal * (1 + tan_a)}, magnitude);
            }
            std::printf(
                "at %g %s: %d rays, %d ambiguous, %d wrong; worst |t - t_ref| %.3g of the tolerance, %.3g "
                "ulps of %g along the normal\n",
                m, name, tally.rays, tally.ambiguous, tally.wrong, tally.worst_t, tally.worst_ulps, magnitude);
            EXPECT_EQ(tally.wrong, 0);
            EXPECT_LT(tally.ambiguous, tally.rays / 20) << "too many rays within the tolerance of an edge";
        }
    }
}

// ------------------------------------------------------------ closest hit

// Six triangles over the same region at heights z: the top one, a coplanar
// copy of it (equal t), one a float ulp of z below it (t differs by less
// than t's float spacing), and three clearly below (by 2^-15, 2^-13 and
// 0.25). The tolerance on t is that of expect_hit_on: 4 ulps of the ray's
// coordinates (at most 27 here: 2^-19 each) along the normal, over |n . d|,
// plus 4 ulps of t (near 9: 2^-20 each), at most 1.2e-5; 2^-15 is 3.1e-5,
// so only the top three tie. Arranged four ways side by side: as
// primitives of one geometry in one order, the same reversed, as six
// geometries of one bottom level, and as six instances of a one-triangle
// bottom level moved up by their transforms. The spec's
// "Ray Closest Hit Determination": a confirmed hit with t = tmax "may: be set
// as the current closest hit or dropped", so a tie may go to either; what
// is closer by more than the tolerance must win. Every layer is a
// candidate (the count is 6).
TEST_F(RayPrecisionTest, ClosestHitAmongOverlappingTrianglesAtNearlyEqualT) {
    const float top = 1.0f + 0x1p-14f;
    const float levels[6] = {top - 0.25f, top - 0x1p-13f, top - 0x1p-15f, std::nextafter(top, 0.0f), top, top};
    const auto layer = [](float z) { return Geometry{{0, 0, z, 4, 0, z, 0, 4, z}, {0, 1, 2}}; };
    Geometry in_order, reversed;
    for (int k = 0; k < 6; ++k) {
        const Geometry l = layer(levels[k]);
        for (Geometry* g : {&in_order, &reversed}) {
            const auto base = std::uint32_t(g->vertices.size() / 3);
            g->vertices.insert(g->vertices.end(), l.vertices.begin(), l.vertices.end());
            g->indices.insert(g->indices.end(), {base, base + 1, base + 2});
        }
    }
    // reversed: the same triangles, primitive k being level 5 - k
    std::reverse(reversed.indices.begin(), reversed.indices.end());
    for (std::size_t t = 0; t < reversed.indices.size(); t += 3)
        std::swap(reversed.indices[t], reversed.indices[t + 2]);
    SceneDesc scene;
    std::vector<Geometry> separate;
    for (float z : levels) separate.push_back(layer(z));
    scene.blases = {{in_order}, {reversed}, separate, {layer(0)}};
    scene.instances = {
        {0, vkrc_test::placed(0, 0, 0), 10}, {1, vkrc_test::placed(8, 0, 0), 11}, {2, vkrc_test::placed(16, 0, 0), 12}};
    for (std::uint32_t k = 0; k < 6; ++k) {
        const std::uint32_t order[6] = {3, 0, 5, 1, 4, 2};  // instance order unlike height order
        scene.instances.push_back({3, vkrc_test::placed(24, 0, levels[order[k]]), 20 + order[k]});
    }
    const auto triangles = world_triangles(scene);
    std::vector<GpuRay> rays;
    for (int arrangement = 0; arrangement < 4; ++arrangement) {
        for (double x : {0.5, 1.25, 2.0}) {
            for (double y : {0.5, 1.0, 1.75}) {
                const Vec target{8.0 * arrangement + x, y, 1};
                for (const Vec& d : {Vec{0, 0, -1}, Vec{0.25, -0.5, -1}, Vec{-0.125, 0.25, -2}}) {
                    rays.push_back(make_ray(target - 9.0 * d, d));
                }
            }
        }
    }
    const auto hits = trace(build(scene), rays);
    Tally tally;
    int went_to[3] = {};  // the tied: the top one first built, its copy, the one an ulp below
    for (std::size_t i = 0; i < rays.size(); ++i) {
        ++tally.rays;
        const GpuRay& r = rays[i];
        const GpuHit& h = hits[i];
        const Vec o = origin_of(r), d = direction_of(r);
        std::vector<std::pair<double, const WorldTriangle*>> crossed;
        for (const auto& tri : triangles) {
            const PlaneHit p = plane_hit(o, d, tri);
            if (p.touches() && !p.on_boundary() && p.t > 0) crossed.emplace_back(p.t, &tri);
        }
        ASSERT_EQ(crossed.size(), 6u) << "each ray crosses the six layers of one arrangement";
        std::stable_sort(crossed.begin(), crossed.end(),
                         [](const auto& a, const auto& b) { return a.first < b.first; });
        const Tolerance tol{4 * float_ulp(max_abs(o)), 4 * float_ulp(max_abs(o))};
        const double tol_t = tol.normal / std::fabs(d.z) + 4 * float_ulp(crossed[0].first);
        std::vector<const WorldTriangle*> allowed;
        for (const auto& [t, tri] : crossed) {
            if (t - crossed[0].first <= tol_t) allowed.push_back(tri);
        }
        ASSERT_EQ(allowed.size(), 3u) << "the top, its copy and the one an ulp below tie";
        const auto it = std::find_if(allowed.begin(), allowed.end(), [&](const WorldTriangle* t) { return is(h, *t); });
        if (h.candidates != 6 || it == allowed.end()) {
            tally.fail("expected the top of 6 layers: " + describe(r, h));
            continue;
        }
        ++went_to[it - allowed.begin()];
        expect_hit_on(tally, r, h, **it, tol, max_abs(o));
    }
    std::printf(
        "%d rays over 6 layers: %d wrong; the closest hit was the top layer built first %d times, its copy %d "
        "times, the layer an ulp below %d times; worst |t - t_ref| %.3g of the tolerance\n",
        tally.rays, tally.wrong, went_to[0], went_to[1], went_to[2], tally.worst_t);
    EXPECT_EQ(tally.wrong, 0);
}

// ------------------------------------------------------------ drop order

// Where a round drops a handle, in the order a round passes them: before
// recording, after begin (before the build step), before the trace, after
// the trace (before end), after end, after the gated submit, after the wait.
enum class Slot { before_begin, before_build, before_trace, after_trace, after_end, after_submit, after_wait };
constexpr int slots = 7;

// What a round's gated command buffer does before it traces.
enum class Work {
    build,    // builds the bottom and top levels (and writes the set then)
    trace,    // nothing: the levels were built, and waited for, before
    rebuild,  // rebuilds the top level built before, with other instances
};
constexpr int work_kinds = 3;

struct FuzzCoverage {
    int work[work_kinds] = {};
    int fresh_devices = 0;
    int unwaited = 0;
    int drops[slots] = {};
};

// A 2 x 2 grid (cells of 2) and a triangle, in 1 (at least first_used) to
// 3 instances at distinct heights, some moved by 1 in x, custom indices
// random; the first first_used instances are of each bottom level in turn
// (so that the top level keeps them all).
SceneDesc fuzz_scene(std::mt19937& rng, unsigned first_used) {
    SceneDesc scene;
    scene.blases = {{grid(2, 2.0)}, {Geometry{{0, 0, 0, 3, 0, 0, 0, 3, 0}, {0, 1, 2}}}};
    const unsigned least = std::max(first_used, 1u);
    const auto count = least + rng() % (4 - least);
    for (unsigned k = 0; k < count; ++k) {
        scene.instances.push_back({k < first_used ? k : rng() % 2, vkrc_test::placed(float(rng() % 2), 0, float(k)),
                                   std::uint32_t(rng() % 1000)});
    }
    return scene;
}

// 25 rays straight down over [0.35, 4.15]^2, off every edge of fuzz_scene's triangles.
std::vector<GpuRay> fuzz_rays() {
    std::vector<GpuRay> rays;
    for (int j = 0; j < 5; ++j) {
        for (int i = 0; i < 5; ++i) rays.push_back(make_ray({0.35 + 0.9 * i, 0.55 + 0.9 * j, 10}, {0, 0, -1}, 100));
    }
    return rays;
}

// Each hit is the reference's closest (these scenes have no ties and no ray on an edge).
::testing::AssertionResult closest_hits_match(const SceneDesc& scene, const std::vector<GpuRay>& rays,
                                              const std::vector<GpuHit>& hits) {
    const auto triangles = world_triangles(scene);
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const WorldTriangle* nearest = nullptr;
        double nearest_t = 0;
        for (const auto& tri : triangles) {
            const PlaneHit p = plane_hit(origin_of(rays[i]), direction_of(rays[i]), tri);
            if (p.on_boundary()) return ::testing::AssertionFailure() << "the reference finds a ray on an edge";
            if (p.touches() && p.t > 0 && (!nearest || p.t < nearest_t)) {
                nearest = &tri;
                nearest_t = p.t;
            }
        }
        const bool right =
            nearest ? is(hits[i], *nearest) && std::fabs(hits[i].t - nearest_t) < 1e-5 : hits[i].committed == 0;
        if (!right) {
            return ::testing::AssertionFailure() << describe(rays[i], hits[i]) << " | expected "
                                                 << (nearest ? "custom " + std::to_string(nearest->custom_index) +
                                                                   " primitive " + std::to_string(nearest->primitive)
                                                             : std::string("a miss"));
        }
    }
    return ::testing::AssertionSuccess();
}

// A round's completion semaphore and gate; the gate goes first, waiting for
// the device to be idle before either is destroyed (see GpuGate).
struct FuzzSync {
    vkrc::Semaphore done;
    vkrc_test::GpuGate gate;
    explicit FuzzSync(const vkrc::Device& device) : done(vkrc::Semaphore::create_timeline(device)), gate(device) {}
};

// One round: a scene's bottom and top levels, the set that holds the top
// level, the ray buffer, the pipeline, its layouts, the command pool, the
// device and the queue, each held by this round's one handle and dropped at
// a random slot no earlier than the last step that uses it, in a random
// order; the build inputs go as soon as the build is recorded. What goes
// after the submit goes while the GPU certainly still needs it (the gate
// opens only after). Every round reads back the hits and checks them
// against the reference's closest hits of the scene the work left.
struct FuzzRound {
    std::mt19937& rng;
    FuzzCoverage& coverage;
    vkrc::Device device;
    vkrc::Queue queue;
    Tracer tracer;
    std::vector<vkrc::AccelerationStructure> blases;
    vkrc::AccelerationStructure top;
    vkrc::DescriptorPool set_pool;
    vkrc::DescriptorSet set;
    vkrc::Buffer rays;
    vkrc::CommandPool pool;
    vkrc::CommandBuffer cmd;
    vkrc::Fence fence;

    int pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng); }

    void run(bool wait) {
        const FuzzSync sync(device);
        const auto& [done, gate] = sync;
        const auto work = static_cast<Work>(pick(work_kinds));
        ++coverage.work[static_cast<int>(work)];
        const auto allocator = vkrc::make_allocator<vkrc_test::CountingAllocator>();
        const SceneDesc built = fuzz_scene(rng, 2);
        SceneDesc traced = built;
        if (work == Work::rebuild) {
            // No more instances than the first build: rebuild_top_level reuses its structure.
            traced.instances = fuzz_scene(rng, 0).instances;
            traced.instances.resize(std::min(traced.instances.size(), built.instances.size()));
        }
        if (work != Work::build) {
            vkrc_test::OneShotCommands s(queue);
            top = record_scene(s.cmd, built, blases, allocator);
            s.run(queue);
        }
        device.collect_garbage();  // the builds' scratch and instances
        const int frees_before = allocator->frees();
        const std::vector<GpuRay> ray_list = fuzz_rays();
        rays = ray_buffer(device, ray_list);
        const vkrc::Buffer hits = hit_buffer(device, ray_list.size());  // kept: read every round
        set_pool = make_set_pool(device, 1);
        pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
        cmd = pool.allocate();
        fence = vkrc::Fence::create(device);
        const auto write_set = [&] {
            set = set_pool.allocate(tracer.set_layout);
            set.write_acceleration_structure(0, top);
            set.write_buffer(1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, rays);
            set.write_buffer(2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, hits);
        };

        struct Item {
            std::function<void()> drop;
            Slot slot;
        };
        std::vector<Item> items;
        auto add = [&](auto& handle, Slot earliest) {
            const auto slot = static_cast<Slot>(static_cast<int>(earliest) + pick(slots - static_cast<int>(earliest)));
            items.push_back({[&handle] { handle = {}; }, slot});
        };
        // The set is written before recording, but for Work::build after its build step.
        const Slot set_made = work == Work::build ? Slot::before_trace : Slot::before_begin;
        // The levels: made by Work::build's step, read by Work::rebuild's, else kept by the set.
        const Slot levels_used = work == Work::trace ? Slot::before_begin : Slot::before_trace;
        blases.resize(built.blases.size());  // Work::build fills them in place
        add(blases[0], levels_used);
        add(blases[1], levels_used);
        add(top, levels_used);
        add(rays, set_made);
        add(set_pool, set_made);
        add(tracer.set_layout, set_made);
        add(set, Slot::after_trace);
        add(tracer.pipeline, Slot::after_trace);
        add(tracer.layout, Slot::after_trace);
        add(device, Slot::before_begin);
        add(queue, Slot::before_begin);
        add(pool, Slot::before_begin);
        add(cmd, Slot::after_submit);  // needed to submit
        add(fence, wait ? Slot::after_wait : Slot::after_submit);
        std::shuffle(items.begin(), items.end(), rng);
        for (const auto& item : items) ++coverage.drops[static_cast<int>(item.slot)];
        auto drop_at = [&](Slot s) {
            for (auto& item : items) {
                if (item.slot == s) item.drop();
            }
        };

        if (work != Work::build) write_set();
        drop_at(Slot::before_begin);
        cmd.begin();
        drop_at(Slot::before_build);
        if (work == Work::build) {
            top = record_scene(cmd, traced, blases, allocator);
            write_set();
        } else if (work == Work::rebuild) {
            // The trace that built the levels was waited for: no hazard on the top level.
            vkrc::rebuild_top_level(cmd, top, top_level_info(traced, blases, allocator));
        }
        drop_at(Slot::before_trace);
        record_trace(cmd, tracer, set, std::uint32_t(ray_list.size()));
        drop_at(Slot::after_trace);
        cmd.end();
        drop_at(Slot::after_end);
        const auto submit_queue = queue ? queue : cmd.pool().device().default_queue();
        const auto held = gate.wait();
        const vkrc::SemaphoreSubmit finished{done, 1};
        vkrc::submit(
            submit_queue,
            {.waits = std::span(&held, 1), .command_buffers = std::span(&cmd, 1), .signals = std::span(&finished, 1)},
            fence);
        drop_at(Slot::after_submit);
        EXPECT_EQ(done.value(), 0u) << "the work ran before the gate opened";
        // Whatever of the levels' memory is gone, the held work may read: none may be.
        EXPECT_EQ(allocator->frees(), frees_before) << "level memory freed while traces of it were held";
        gate.open();
        if (wait) {
            ASSERT_EQ(fence.wait(), VK_SUCCESS);
        } else {
            ASSERT_EQ(done.wait(1), VK_SUCCESS);
            ++coverage.unwaited;
        }
        std::vector<GpuHit> got(ray_list.size());
        hits.allocation().read(0, got.data(), got.size());
        ASSERT_TRUE(closest_hits_match(traced, ray_list, got)) << "work " << static_cast<int>(work);
        drop_at(Slot::after_wait);
    }
};

// Rounds on the fixture's device (dropping copies of its tracer) and, every
// eighth, on a fresh device with a tracer of its own, which the round may
// drop with everything else while its work is held. One round in four (one
// in two of those on a fresh device) waits on the completion semaphore,
// not the fence, which may then be dropped with the work in flight. The
// seed comes from VKRC_TEST_SEED when set (test_seed), to replay a run.
TEST_F(RayPrecisionTest, RandomDropsOfLevelsAndSetsWithTracesInFlight) {
    const auto seed = vkrc_test::test_seed();
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937 rng(seed);
    FuzzCoverage coverage;
    for (int round = 0; round < 64; ++round) {
        SCOPED_TRACE("round " + std::to_string(round));
        FuzzRound r{rng, coverage, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}};
        const bool fresh = round % 8 == 7;
        if (fresh) {
            r.device = vkrc_test::ray_query_device(physical_device);
            r.tracer = make_tracer(r.device);
            ++coverage.fresh_devices;
        } else {
            r.device = device;
            r.tracer = tracer;
        }
        r.queue = r.device.default_queue();
        r.run(fresh ? r.pick(2) != 0 : r.pick(4) != 0);
        if (HasFatalFailure()) return;
        const auto messages = log->take();  // here rather than at TearDown, to name the round
        ASSERT_TRUE(messages.empty()) << messages.front();
    }
    std::printf(
        "work: build %d, trace %d, rebuild %d; fresh devices %d, unwaited %d; drops before begin %d, before "
        "the build %d, before the trace %d, after the trace %d, after end %d, after submit %d, after wait "
        "%d\n",
        coverage.work[0], coverage.work[1], coverage.work[2], coverage.fresh_devices, coverage.unwaited,
        coverage.drops[0], coverage.drops[1], coverage.drops[2], coverage.drops[3], coverage.drops[4],
        coverage.drops[5], coverage.drops[6]);
    for (int w : coverage.work) EXPECT_GT(w, 0);
    for (int d : coverage.drops) EXPECT_GT(d, 0);
    device.wait_idle();
    EXPECT_EQ(device.deferred_count(), 0u);
}

}  // namespace
