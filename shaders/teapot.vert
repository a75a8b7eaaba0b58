#version 450
// The teapot benchmark's vertex shader: per-teapot world matrix and colour in
// push constants (80 bytes), shared camera in a uniform buffer.

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;

layout(set = 0, binding = 0) uniform Camera {
    mat4 view;
    mat4 proj;
} camera;

layout(push_constant) uniform Draw {
    mat4 world;
    vec4 colour;
} draw;

layout(location = 0) out vec3 out_normal;
layout(location = 1) out vec4 out_colour;

void main() {
    // The world matrix is a rotation plus translation, so its 3x3 part
    // transforms normals as well.
    out_normal = mat3(draw.world) * in_normal;
    out_colour = draw.colour;
    gl_Position = camera.proj * camera.view * draw.world * vec4(in_position, 1.0);
}
