#version 450
// The colour is specialization constants 0 (red) and 1 (green).
layout(constant_id = 0) const float red = 0.0;
layout(constant_id = 1) const float green = 0.0;
layout(location = 0) out vec4 out_color;
void main() { out_color = vec4(red, green, 0.0, 1.0); }
