#version 450
// examples/renderer: the depth-only shadow pass, in the light's clip space.

layout(location = 0) in vec3 in_position;

layout(set = 0, binding = 0) uniform Frame {
    mat4 view_proj;
    mat4 light_view_proj;
    vec4 light_direction;
    vec4 camera_position;
} frame;

layout(push_constant) uniform Draw {
    mat4 world;
    uint texture_index;
    float uv_scale;
} draw;

void main() { gl_Position = frame.light_view_proj * draw.world * vec4(in_position, 1.0); }
