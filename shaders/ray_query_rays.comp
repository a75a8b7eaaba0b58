#version 460
// One ray per invocation, given explicitly (origin, tmin, direction, tmax),
// traced twice against the top level at binding 0, seen by every instance
// (cull mask 0xFF):
// - as opaque (gl_RayFlagsOpaqueEXT): the closest committed hit's t, instance
//   custom index, instance index, geometry index, primitive ID and
//   barycentrics, or a miss;
// - as non-opaque (gl_RayFlagsNoOpaqueEXT), confirming nothing, so that tmax
//   never shrinks and every candidate along the ray comes back: how many,
//   and the first 8 as instance index << 24 | primitive ID. With
//   NO_DUPLICATE_ANY_HIT geometry each intersection is reported once, so a
//   ray through a shared edge that hits both triangles counts 2.
#extension GL_EXT_ray_query : require

layout(local_size_x = 64) in;

struct Ray {
    vec4 origin_tmin;
    vec4 direction_tmax;
};

// 68 bytes, scalars only (std430 packs them as the C++ struct does).
struct Hit {
    float t;
    uint custom_index;
    uint instance;
    uint geometry;
    uint primitive;
    float u;
    float v;
    uint committed;  // 1: a triangle hit, 0: a miss
    uint candidates;
    uint candidate_ids[8];
};

layout(set = 0, binding = 0) uniform accelerationStructureEXT scene;
layout(set = 0, binding = 1, std430) readonly buffer Rays { Ray rays[]; };
layout(set = 0, binding = 2, std430) writeonly buffer Hits { Hit hits[]; };

layout(push_constant) uniform Params {
    uint count;
};

void main() {
    const uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    const Ray r = rays[i];
    Hit h;
    h.t = 0.0;
    h.custom_index = h.instance = h.geometry = h.primitive = 0xFFFFFFFFu;
    h.u = h.v = 0.0;
    h.committed = 0u;

    rayQueryEXT closest;
    rayQueryInitializeEXT(closest, scene, gl_RayFlagsOpaqueEXT, 0xFF, r.origin_tmin.xyz, r.origin_tmin.w,
                          r.direction_tmax.xyz, r.direction_tmax.w);
    while (rayQueryProceedEXT(closest)) {
    }
    if (rayQueryGetIntersectionTypeEXT(closest, true) == gl_RayQueryCommittedIntersectionTriangleEXT) {
        h.t = rayQueryGetIntersectionTEXT(closest, true);
        h.custom_index = uint(rayQueryGetIntersectionInstanceCustomIndexEXT(closest, true));
        h.instance = uint(rayQueryGetIntersectionInstanceIdEXT(closest, true));
        h.geometry = uint(rayQueryGetIntersectionGeometryIndexEXT(closest, true));
        h.primitive = uint(rayQueryGetIntersectionPrimitiveIndexEXT(closest, true));
        const vec2 b = rayQueryGetIntersectionBarycentricsEXT(closest, true);
        h.u = b.x;
        h.v = b.y;
        h.committed = 1u;
    }

    rayQueryEXT every;
    rayQueryInitializeEXT(every, scene, gl_RayFlagsNoOpaqueEXT, 0xFF, r.origin_tmin.xyz, r.origin_tmin.w,
                          r.direction_tmax.xyz, r.direction_tmax.w);
    h.candidates = 0u;
    for (int k = 0; k < 8; ++k) h.candidate_ids[k] = 0xFFFFFFFFu;
    while (rayQueryProceedEXT(every)) {
        if (rayQueryGetIntersectionTypeEXT(every, false) == gl_RayQueryCandidateIntersectionTriangleEXT) {
            if (h.candidates < 8u) {
                h.candidate_ids[h.candidates] = uint(rayQueryGetIntersectionInstanceIdEXT(every, false)) << 24 |
                                                uint(rayQueryGetIntersectionPrimitiveIndexEXT(every, false));
            }
            ++h.candidates;
        }
    }
    hits[i] = h;
}
