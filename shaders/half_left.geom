#version 450
// Squeezes each triangle into the left half (x from -1..1 to -1..0), so a
// test sees that the geometry stage ran.
layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;
void main() {
    for (int i = 0; i < 3; ++i) {
        vec4 p = gl_in[i].gl_Position;
        gl_Position = vec4(p.x * 0.5 - 0.5, p.yzw);
        EmitVertex();
    }
    EndPrimitive();
}
