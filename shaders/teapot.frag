#version 450
// The teapot benchmark's fragment shader: one directional light, ambient term.

layout(location = 0) in vec3 in_normal;
layout(location = 1) in vec4 in_colour;

layout(location = 0) out vec4 out_colour;

const vec3 light_direction = vec3(0.408248, 0.816497, 0.408248);  // towards the light, unit

void main() {
    vec3 n = normalize(in_normal);
    float diffuse = max(dot(n, light_direction), 0.0);
    out_colour = vec4(in_colour.rgb * (0.2 + 0.8 * diffuse), 1.0);
}
