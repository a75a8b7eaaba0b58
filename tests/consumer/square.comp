#version 450
// data[i] = i * i for i < count.
layout(local_size_x = 64) in;
layout(set = 0, binding = 0, std430) buffer Out { uint data[]; };
layout(push_constant) uniform Params { uint count; } params;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < params.count) data[i] = i * i;
}
