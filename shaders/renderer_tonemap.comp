#version 450
// examples/renderer: tone-maps the resolved HDR image into an 8-bit image
// (the presented one, or an intermediate that is then blitted) with ACES
// (Narkowicz's fit) and the sRGB transfer curve. A NaN or infinite input
// pixel comes out magenta, so that the image check finds it.
layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform sampler2D hdr;
layout(set = 0, binding = 1, rgba8) uniform writeonly image2D ldr;

const float exposure = 1.0;

vec3 aces(vec3 x) { return clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0); }

vec3 srgb(vec3 c) { return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c)); }

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(ldr)))) return;
    vec3 c = texelFetch(hdr, p, 0).rgb;
    bool bad = any(isnan(c)) || any(isinf(c));
    imageStore(ldr, p, vec4(bad ? vec3(1.0, 0.0, 1.0) : srgb(aces(c * exposure)), 1.0));
}
