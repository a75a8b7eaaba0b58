#version 450
// Fetches every texel of one mip level of a sampled texture into data
// (packed RGBA8 unorm), for the streaming tests' texel-by-texel check.
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform sampler2D tex;
layout(set = 0, binding = 1, std430) buffer Out { uint data[]; };
layout(push_constant) uniform Params { int level; uint width; uint height; uint base; } params;
void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= params.width || p.y >= params.height) return;
    data[params.base + p.y * params.width + p.x] = packUnorm4x8(texelFetch(tex, ivec2(p), params.level));
}
