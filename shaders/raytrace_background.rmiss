#version 460
#extension GL_EXT_ray_tracing : require
// examples/raytrace: a primary ray that hits nothing shows the background,
// the rasterising paths' clear colour (scene.hpp), from this record's data.
layout(shaderRecordEXT, std430) buffer Record { vec4 background; };
layout(location = 0) rayPayloadInEXT vec3 colour;

void main() { colour = background.rgb; }
