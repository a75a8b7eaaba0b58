#version 460
// One orthographic ray per pixel, from z = 10 towards -z through the pixel's
// centre (x + 0.5, y + 0.5) in world units, traced with a ray query against
// the top level at binding 0. Writes, per pixel, 0xFFFFFFFF for a miss or
// the closest hit's instance custom index << 8 | geometry index.
#extension GL_EXT_ray_query : require

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform accelerationStructureEXT scene;
layout(set = 0, binding = 1, std430) writeonly buffer Hits { uint hits[]; };

layout(push_constant) uniform Params {
    uint width;
    uint height;
    uint cull_mask;
};

void main() {
    const uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= width || p.y >= height) return;
    const vec3 origin = vec3(float(p.x) + 0.5, float(p.y) + 0.5, 10.0);
    rayQueryEXT query;
    rayQueryInitializeEXT(query, scene, gl_RayFlagsOpaqueEXT, cull_mask, origin, 0.0, vec3(0.0, 0.0, -1.0), 100.0);
    while (rayQueryProceedEXT(query)) {
    }
    uint hit = 0xFFFFFFFFu;
    if (rayQueryGetIntersectionTypeEXT(query, true) == gl_RayQueryCommittedIntersectionTriangleEXT) {
        hit = uint(rayQueryGetIntersectionInstanceCustomIndexEXT(query, true)) << 8 |
              uint(rayQueryGetIntersectionGeometryIndexEXT(query, true));
    }
    hits[p.y * width + p.x] = hit;
}
