#version 460
// ray_query.comp's trace from a fragment shader: one orthographic ray per
// pixel, from z = 10 towards -z through the pixel's centre (gl_FragCoord.xy,
// in world units), against the top level at binding 0. Writes 0xFFFFFFFF
// for a miss or the closest hit's instance custom index << 8 | geometry
// index to an R32_UINT attachment.
#extension GL_EXT_ray_query : require

layout(set = 0, binding = 0) uniform accelerationStructureEXT scene;

layout(push_constant) uniform Params {
    uint cull_mask;
};

layout(location = 0) out uint hit;

void main() {
    const vec3 origin = vec3(gl_FragCoord.xy, 10.0);
    rayQueryEXT query;
    rayQueryInitializeEXT(query, scene, gl_RayFlagsOpaqueEXT, cull_mask, origin, 0.0, vec3(0.0, 0.0, -1.0), 100.0);
    while (rayQueryProceedEXT(query)) {
    }
    hit = 0xFFFFFFFFu;
    if (rayQueryGetIntersectionTypeEXT(query, true) == gl_RayQueryCommittedIntersectionTriangleEXT) {
        hit = uint(rayQueryGetIntersectionInstanceCustomIndexEXT(query, true)) << 8 |
              uint(rayQueryGetIntersectionGeometryIndexEXT(query, true));
    }
}
