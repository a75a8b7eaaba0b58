#version 450
#extension GL_GOOGLE_include_directive : require
// examples/raytrace's rasterising path: one indexed draw per instance.
#include "raytrace_scene.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(location = 0) out vec3 out_normal;

void main() { transform(in_position, in_normal, gl_Position, out_normal); }
