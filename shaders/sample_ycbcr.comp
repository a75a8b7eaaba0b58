#version 450
// Samples the centre of every texel of a width x height texture into data
// (packed RGBA8 unorm), for the Y'CbCr tests: a sampler with a Y'CbCr
// conversion converts on texture lookups, which texelFetch is not.
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform sampler2D tex;
layout(set = 0, binding = 1, std430) buffer Out { uint data[]; };
layout(push_constant) uniform Params { uint width; uint height; } params;
void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= params.width || p.y >= params.height) return;
    vec2 uv = (vec2(p) + 0.5) / vec2(params.width, params.height);
    data[p.y * params.width + p.x] = packUnorm4x8(textureLod(tex, uv, 0.0));
}
