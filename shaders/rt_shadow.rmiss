#version 460
// A shadow ray that reaches the light unblocked.
#extension GL_EXT_ray_tracing : require

layout(location = 1) rayPayloadInEXT uint shadowed;

void main() { shadowed = 0u; }
