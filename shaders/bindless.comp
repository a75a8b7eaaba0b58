#version 450
#extension GL_EXT_nonuniform_qualifier : require
// Invocation i reads the one texel of textures[10 + (i * 3) % 8], an index
// that differs across the invocations, from a partially bound,
// variable-count array, and stores it in data[i]. nonuniformEXT goes on the
// combined sampler the access uses: on the index alone glslang leaves the
// OpSampledImage undecorated, and lavapipe then reads textures[10] for all.
layout(local_size_x = 8) in;
layout(set = 0, binding = 0, std430) buffer Out { uint data[]; };
layout(set = 0, binding = 1) uniform sampler nearest;
layout(set = 0, binding = 2) uniform utexture2D textures[];
void main() {
    uint i = gl_LocalInvocationID.x;
    uint slot = 10u + (i * 3u) % 8u;
    data[i] = texelFetch(nonuniformEXT(usampler2D(textures[slot], nearest)), ivec2(0), 0).x;
}
