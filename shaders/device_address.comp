#version 450
#extension GL_EXT_buffer_reference : require
// Reads and writes through buffer device addresses passed as push constants:
// dst.values[i] = src.values[i] * 3 + 1 for i < count.
layout(local_size_x = 64) in;
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer Src { uint values[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer Dst { uint values[]; };
layout(push_constant) uniform Params { Src src; Dst dst; uint count; } params;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < params.count) params.dst.values[i] = params.src.values[i] * 3u + 1u;
}
