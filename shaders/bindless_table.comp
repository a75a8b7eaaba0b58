#version 450
#extension GL_EXT_nonuniform_qualifier : require
// Copies the one texel of four textures of a vkrc::BindlessTable into a
// buffer of the same table (tests/bindless_table_test.cpp). Each index is
// the same for the whole dispatch (dynamically uniform).
layout(local_size_x = 1) in;
layout(set = 0, binding = 0) uniform usampler2D textures[];
layout(set = 0, binding = 1, std430) buffer Out { uint data[]; } buffers[];
layout(push_constant) uniform Params { uint out_index; uint base; uint count; uint texture[4]; } params;
void main() {
    for (uint i = 0; i < params.count; ++i)
        buffers[params.out_index].data[params.base + i] = texelFetch(textures[params.texture[i]], ivec2(0), 0).x;
}
