#version 450
// An axis-aligned rectangle (6 vertices, counter-clockwise in framebuffer
// space) at one depth, all from push constants: no vertex buffer needed.
layout(push_constant) uniform Rect { vec4 color; vec4 bounds; float depth; } rect;  // bounds: x0 y0 x1 y1 (NDC)
void main() {
    const ivec2 corners[6] = ivec2[](ivec2(0, 0), ivec2(0, 1), ivec2(1, 1), ivec2(0, 0), ivec2(1, 1), ivec2(1, 0));
    ivec2 c = corners[gl_VertexIndex];
    gl_Position = vec4(c.x == 0 ? rect.bounds.x : rect.bounds.z, c.y == 0 ? rect.bounds.y : rect.bounds.w, rect.depth, 1.0);
}
