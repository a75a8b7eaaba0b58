#version 450
// A full-screen-height rectangle (counter-clockwise) whose right edge, in
// NDC, is specialization constant 0.
layout(constant_id = 0) const float right = 1.0;
void main() {
    const vec2 corners[6] = vec2[](vec2(-1, -1), vec2(-1, 1), vec2(right, 1), vec2(-1, -1), vec2(right, 1), vec2(right, -1));
    gl_Position = vec4(corners[gl_VertexIndex], 0.0, 1.0);
}
