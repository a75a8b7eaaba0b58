#version 450
#extension GL_EXT_nonuniform_qualifier : require
// examples/renderer: the material's texture from the bindless table (its
// index in push constants), a directional light shadowed through the shadow
// map (3x3 comparison taps, each itself a filtered 2x2 comparison), an
// ambient sky term. Writes linear HDR colour.

layout(location = 0) in vec3 in_normal;
layout(location = 1) in vec3 in_world;
layout(location = 2) in vec2 in_uv;
layout(location = 3) in vec4 in_light_clip;

layout(set = 0, binding = 0) uniform Frame {
    mat4 view_proj;
    mat4 light_view_proj;
    vec4 light_direction;
    vec4 camera_position;
} frame;
layout(set = 0, binding = 1) uniform sampler2DShadow shadow_map;
// The bindless table (vkrc::BindlessTable's binding 0): partially bound,
// only its live slots are written. The index is a push constant, uniform
// across a draw, so it needs no nonuniformEXT.
layout(set = 1, binding = 0) uniform sampler2D textures[];

layout(push_constant) uniform Draw {
    mat4 world;
    uint texture_index;
    float uv_scale;
} draw;

layout(location = 0) out vec4 out_colour;

const vec3 sun = vec3(1.8, 1.7, 1.5);
const vec3 sky = vec3(0.10, 0.12, 0.16);

float lit_fraction() {
    vec3 p = in_light_clip.xyz / in_light_clip.w;
    vec2 uv = p.xy * 0.5 + 0.5;
    vec2 texel = 1.0 / vec2(textureSize(shadow_map, 0));
    float sum = 0.0;
    for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) sum += texture(shadow_map, vec3(uv + vec2(x, y) * texel, p.z));
    return sum / 9.0;
}

void main() {
    vec3 n = normalize(in_normal);
    // The teapot's open spout and lid show inner faces: light the side seen.
    if (dot(n, frame.camera_position.xyz - in_world) < 0.0) n = -n;
    float diffuse = max(dot(n, frame.light_direction.xyz), 0.0);
    vec3 albedo = texture(textures[draw.texture_index], in_uv).rgb;
    out_colour = vec4(albedo * (sky + sun * diffuse * lit_fraction()), 1.0);
}
