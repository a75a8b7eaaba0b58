#version 450
// Copies a uniform block's value into data[index], for the streaming tests'
// check of dynamic uniform offsets into a FrameRing.
layout(local_size_x = 1) in;
layout(set = 0, binding = 0) uniform Block { uint value; } block;
layout(set = 0, binding = 1, std430) buffer Out { uint data[]; };
layout(push_constant) uniform Params { uint index; } params;
void main() { data[params.index] = block.value; }
