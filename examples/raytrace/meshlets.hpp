// Meshlets for examples/raytrace's mesh-shader path, free of Vulkan: a
// triangle list cut, greedily in index order, into groups of at most
// max_vertices distinct vertices and max_triangles triangles, the sizes
// one mesh shader workgroup emits (shaders/raytrace_mesh.mesh). Index order
// is kept, so the triangles reach the rasteriser in the order a vertex
// shader draw gives them (primitive order: workgroups in order, then
// primitives within one), which keeps the two paths' images identical.
#pragma once

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace raytrace {

// One meshlet: its vertices are vertices[vertex_offset, + vertex_count) of
// Meshlets, its triangles triangles[triangle_offset, + triangle_count).
// Four uints, as the shader reads them (a uvec4 in a std430 array).
struct Meshlet {
    std::uint32_t vertex_offset = 0;
    std::uint32_t vertex_count = 0;
    std::uint32_t triangle_offset = 0;
    std::uint32_t triangle_count = 0;
};
static_assert(sizeof(Meshlet) == 16);

struct MeshletLimits {
    // At most 256: a triangle's corners are 8-bit meshlet-local indices.
    std::uint32_t max_vertices = 64;
    std::uint32_t max_triangles = 124;
};

// Meshlets of one or more meshes, appended to the same arrays.
struct Meshlets {
    std::vector<Meshlet> meshlets;
    // The mesh's vertex index (plus the base vertex given to append_meshlets).
    std::vector<std::uint32_t> vertices;
    // A triangle's three meshlet-local vertex indices, 8 bits each, the
    // first in the lowest byte.
    std::vector<std::uint32_t> triangles;
};

inline std::uint32_t pack_triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) { return a | b << 8 | c << 16; }
inline std::uint32_t triangle_corner(std::uint32_t packed, int corner) { return packed >> (8 * corner) & 0xffu; }

// Cuts the triangle list indices into meshlets and appends them to out; a
// vertex index v is stored as base_vertex + v. Returns how many meshlets
// were appended (their first is the old out.meshlets.size()). Throws
// std::invalid_argument for limits outside 3..256 vertices and 1.. triangles,
// or an index count that is not a multiple of 3.
template <typename Index>
std::uint32_t append_meshlets(std::span<const Index> indices, Meshlets& out, std::uint32_t base_vertex = 0,
                              MeshletLimits limits = {}) {
    if (limits.max_vertices < 3 || limits.max_vertices > 256 || limits.max_triangles < 1)
        throw std::invalid_argument("raytrace::append_meshlets: limits of " + std::to_string(limits.max_vertices) +
                                    " vertices and " + std::to_string(limits.max_triangles) +
                                    " triangles (want 3..256 and at least 1)");
    if (indices.size() % 3 != 0)
        throw std::invalid_argument("raytrace::append_meshlets: " + std::to_string(indices.size()) +
                                    " indices, not a multiple of 3");
    const std::size_t first = out.meshlets.size();
    // local[v]: v's index in the meshlet being filled, or none.
    constexpr std::uint32_t none = UINT32_MAX;
    std::vector<std::uint32_t> local;
    Meshlet m{std::uint32_t(out.vertices.size()), 0, std::uint32_t(out.triangles.size()), 0};
    auto close = [&] {
        for (std::uint32_t i = 0; i < m.vertex_count; ++i)
            local[out.vertices[m.vertex_offset + i] - base_vertex] = none;
        out.meshlets.push_back(m);
        m = {std::uint32_t(out.vertices.size()), 0, std::uint32_t(out.triangles.size()), 0};
    };
    for (std::size_t t = 0; t < indices.size(); t += 3) {
        const std::uint32_t v[3] = {indices[t], indices[t + 1], indices[t + 2]};
        std::uint32_t added = 0;  // distinct vertices of the triangle not yet in the meshlet
        for (int c = 0; c < 3; ++c) {
            if (v[c] >= local.size()) local.resize(v[c] + 1, none);
            added += local[v[c]] == none && (c == 0 || v[c] != v[0]) && (c < 2 || v[c] != v[1]);
        }
        if (m.vertex_count + added > limits.max_vertices || m.triangle_count == limits.max_triangles) close();
        std::uint32_t corner[3];
        for (int c = 0; c < 3; ++c) {
            if (local[v[c]] == none) {
                local[v[c]] = m.vertex_count++;
                out.vertices.push_back(base_vertex + v[c]);
            }
            corner[c] = local[v[c]];
        }
        out.triangles.push_back(pack_triangle(corner[0], corner[1], corner[2]));
        ++m.triangle_count;
    }
    if (m.triangle_count > 0) close();
    return std::uint32_t(out.meshlets.size() - first);
}

}  // namespace raytrace
