// examples/raytrace's ray-traced path: what its raygen and closest-hit
// shaders share (main.cpp's RayTracedPath). The scene's top level has one
// instance per scene instance, its custom index the instance's index.
layout(set = 0, binding = 0) uniform accelerationStructureEXT scene;

// main.cpp's TraceConstants: the inverse of the rasterising paths'
// view_proj (pixel centres to the near and far planes), the light, and
// whether closest hits cast shadow rays.
layout(push_constant) uniform Trace {
    mat4 inverse_view_proj;
    vec4 light_direction;  // towards the light, unit
    uint shadows;
} trace;

// Payload locations (traceRayEXT's last argument) and miss records (its miss index).
const int primary = 0, shadow = 1;
