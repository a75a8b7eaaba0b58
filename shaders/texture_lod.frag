#version 450
// Samples one mip level of the texture (see examples/texture).
layout(set = 0, binding = 0) uniform sampler2D tex;
layout(push_constant) uniform Params { float lod; } params;
layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 out_color;
void main() { out_color = textureLod(tex, uv, params.lod); }
