#version 460
#extension GL_EXT_ray_tracing : require
// examples/raytrace: a shadow ray that reaches the light unblocked.
layout(location = 1) rayPayloadInEXT float light_visible;

void main() { light_visible = 1.0; }
