// examples/raytrace: the frame's uniforms (examples/raytrace/scene.hpp's
// FrameUniforms), an instance's push constants and the vertex transform,
// shared by the vertex and the mesh shader so that both compute every
// clip-space position with the same operations (their images must match bit
// for bit).
layout(set = 0, binding = 0) uniform Frame {
    mat4 view_proj;
    vec4 light_direction;  // towards the light, unit
} frame;

// An instance (main.cpp's InstanceConstants): first_meshlet is the mesh
// shader's; the vertex shader's draw gives the mesh's indices instead.
layout(push_constant) uniform Draw {
    mat4 world;
    vec4 colour;
    uint first_meshlet;
} draw;

// World matrices are rotation, uniform scale and translation: their 3x3
// part keeps normals' directions.
void transform(vec3 position, vec3 normal, out vec4 clip, out vec3 world_normal) {
    clip = frame.view_proj * (draw.world * vec4(position, 1.0));
    world_normal = mat3(draw.world) * normal;
}
