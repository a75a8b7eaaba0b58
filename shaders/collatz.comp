#version 450
// For each start value, counts the steps of the Collatz sequence to reach 1
// (see examples/compute).
layout(local_size_x = 64) in;
layout(set = 0, binding = 0, std430) readonly buffer Starts { uint starts[]; };
layout(set = 0, binding = 1, std430) writeonly buffer Steps { uint steps[]; };
layout(push_constant) uniform Params { uint count; } params;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= params.count) return;
    uint n = starts[i], s = 0;
    while (n != 1) {
        n = (n % 2 == 0) ? n / 2 : 3 * n + 1;
        ++s;
    }
    steps[i] = s;
}
