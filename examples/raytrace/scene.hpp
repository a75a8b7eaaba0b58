// examples/raytrace's scene, free of Vulkan: examples/renderer's teapots,
// ground and camera (renderer/scene.hpp), each teapot at a fixed
// tessellation level (finer nearer the camera), one directional light. The
// ground and each level in use are one mesh, appended to one set of arrays;
// an instance places a mesh with its world matrix and colour. Every render
// path draws this: the rasteriser and the mesh shader from the arrays, the
// ray tracer from one bottom-level structure per mesh and one instance per
// Instance.
#pragma once

#include "renderer/scene.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

namespace raytrace {

// Tessellation level (quads per patch edge) of renderer::teapots[i], near to far.
inline constexpr std::array<int, renderer::teapots.size()> teapot_levels = {16, 12, 8, 6, 4};
inline constexpr std::array<glm::vec4, 3> colours = {{{0.55f, 0.52f, 0.45f, 1.0f},    // the ground
                                                      {0.80f, 0.25f, 0.18f, 1.0f},    // renderer texture 1's teapots
                                                      {0.20f, 0.35f, 0.80f, 1.0f}}};  // texture 2's
// The clear colour, and what a ray tracer's miss shader returns.
inline constexpr std::array<float, 4> background = {0.45f, 0.6f, 0.9f, 1.0f};

// A mesh: indices [first_index, + index_count) of Geometry::indices, which
// index vertices from vertex_offset of its positions and normals.
struct MeshRange {
    std::uint32_t first_index = 0, index_count = 0;
    std::int32_t vertex_offset = 0;
    std::uint32_t vertex_count = 0;
};
struct Geometry {
    std::vector<glm::vec3> positions, normals;
    std::vector<std::uint16_t> indices;
    std::vector<MeshRange> meshes;
};
struct Instance {
    glm::mat4 world;
    glm::vec4 colour;
    std::uint32_t mesh;  // index into Geometry::meshes
};
struct Scene {
    Geometry geometry;
    std::vector<Instance> instances;  // the ground first, then renderer::teapots in order
    std::vector<int> mesh_levels;     // each mesh's tessellation level; 0 for the ground
};

inline std::uint32_t add_mesh(Geometry& g, const teapot::Mesh& m) {
    g.meshes.push_back({std::uint32_t(g.indices.size()), std::uint32_t(m.indices.size()),
                        std::int32_t(g.positions.size()), std::uint32_t(m.positions.size())});
    g.positions.insert(g.positions.end(), m.positions.begin(), m.positions.end());
    g.normals.insert(g.normals.end(), m.normals.begin(), m.normals.end());
    g.indices.insert(g.indices.end(), m.indices.begin(), m.indices.end());
    return std::uint32_t(g.meshes.size() - 1);
}

inline Scene make_scene() {
    Scene s;
    // The ground: the renderer's square, in the model's z-up xy plane.
    const float h = renderer::ground_half_size;
    const std::vector<glm::vec3> corners = {{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}};
    add_mesh(s.geometry, {corners, std::vector(4, glm::vec3(0, 0, 1)), {0, 1, 2, 0, 2, 3}, {}});
    s.mesh_levels.push_back(0);
    s.instances.push_back(
        {glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.0f, -8.0f)) * renderer::z_up_to_y_up(), colours[0], 0});
    for (std::size_t i = 0; i < renderer::teapots.size(); ++i) {
        const auto level = std::find(s.mesh_levels.begin(), s.mesh_levels.end(), teapot_levels[i]);
        std::uint32_t mesh = std::uint32_t(level - s.mesh_levels.begin());
        if (level == s.mesh_levels.end()) {
            mesh = add_mesh(s.geometry, teapot::tessellate(teapot::newell_teapot(), teapot_levels[i]));
            s.mesh_levels.push_back(teapot_levels[i]);
        }
        const auto& t = renderer::teapots[i];
        s.instances.push_back({renderer::teapot_world(t), colours[t.texture], mesh});
    }
    return s;
}

// Per frame (set 0, binding 0 of every path's shaders, shaders/raytrace_scene.glsl).
struct FrameUniforms {
    glm::mat4 view_proj;
    glm::vec4 light_direction;  // towards the light, unit
};
inline FrameUniforms frame_uniforms(std::uint32_t width, std::uint32_t height) {
    return {renderer::view_projection(width, height), glm::vec4(renderer::light_direction, 0.0f)};
}

}  // namespace raytrace
