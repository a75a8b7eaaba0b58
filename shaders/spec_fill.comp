#version 450
// Specialization constants: the workgroup size (constant 0) and two values;
// each invocation writes value + scale * local index.
layout(local_size_x_id = 0) in;
layout(constant_id = 1) const uint value = 1;
layout(constant_id = 2) const uint scale = 1;
layout(set = 0, binding = 0) buffer Out { uint data[]; };
void main() { data[gl_GlobalInvocationID.x] = value + scale * gl_LocalInvocationID.x; }
