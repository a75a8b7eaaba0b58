#version 450
// examples/renderer: every mesh (teapots and ground, z up in model space)
// with the per-frame uniforms from the frame ring and a per-draw world
// matrix and texture index in push constants.

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;

layout(set = 0, binding = 0) uniform Frame {
    mat4 view_proj;
    mat4 light_view_proj;
    vec4 light_direction;  // towards the light, unit
    vec4 camera_position;
} frame;

layout(push_constant) uniform Draw {
    mat4 world;
    uint texture_index;
    float uv_scale;
} draw;

layout(location = 0) out vec3 out_normal;
layout(location = 1) out vec3 out_world;
layout(location = 2) out vec2 out_uv;
layout(location = 3) out vec4 out_light_clip;

void main() {
    vec4 world = draw.world * vec4(in_position, 1.0);
    // World matrices are rotation, uniform scale and translation: their 3x3
    // part keeps normals' directions.
    out_normal = mat3(draw.world) * in_normal;
    out_world = world.xyz;
    // A planar projection of the model: the ground's plane, the teapot's side.
    out_uv = vec2(in_position.x, in_position.y + in_position.z) * draw.uv_scale;
    out_light_clip = frame.light_view_proj * world;
    gl_Position = frame.view_proj * world;
}
