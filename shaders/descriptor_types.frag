#version 450
// descriptor_types.comp's reads from a fragment shader, plus an input
// attachment (tests/descriptor_refs_test.cpp draws one fragment).
layout(set = 0, binding = 0) uniform U { uint value; } u;
layout(set = 0, binding = 1, std430) readonly buffer S { uint value; } s;
layout(set = 0, binding = 2) uniform UD { uint value; } ud;
layout(set = 0, binding = 3, std430) readonly buffer SD { uint value; } sd;
layout(set = 0, binding = 4) uniform usamplerBuffer uniform_texels;
layout(set = 0, binding = 5, r32ui) uniform readonly uimageBuffer storage_texels;
layout(set = 0, binding = 6) uniform sampler nearest;
layout(set = 0, binding = 7) uniform utexture2D sampled;
layout(set = 0, binding = 8) uniform usampler2D combined;
layout(set = 0, binding = 9, r32ui) uniform readonly uimage2D storage_image;
layout(set = 0, binding = 10, std430) buffer Out { uint data[10]; } out_;
layout(set = 0, binding = 11, input_attachment_index = 0) uniform usubpassInput attachment;
void main() {
    out_.data[0] = u.value;
    out_.data[1] = s.value;
    out_.data[2] = ud.value;
    out_.data[3] = sd.value;
    out_.data[4] = texelFetch(uniform_texels, 0).x;
    out_.data[5] = imageLoad(storage_texels, 0).x;
    out_.data[6] = texelFetch(usampler2D(sampled, nearest), ivec2(0), 0).x;
    out_.data[7] = texelFetch(combined, ivec2(0), 0).x;
    out_.data[8] = imageLoad(storage_image, ivec2(0)).x;
    out_.data[9] = subpassLoad(attachment).x;
}
