#version 450
#extension GL_GOOGLE_include_directive : require
// examples/raytrace's fragment shader, behind the vertex and the mesh shader.
#include "raytrace_scene.glsl"
#include "raytrace_shading.glsl"

layout(location = 0) in vec3 in_normal;
layout(location = 0) out vec4 out_colour;

void main() { out_colour = vec4(shade(in_normal, draw.colour.rgb, frame.light_direction.xyz, 1.0), 1.0); }
