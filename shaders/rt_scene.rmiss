#version 460
// A primary ray that hits nothing: the value of the miss record's data.
#extension GL_EXT_ray_tracing : require

layout(shaderRecordEXT, std430) buffer Record { uint miss_value; };
layout(location = 0) rayPayloadInEXT uint value;

void main() { value = miss_value; }
