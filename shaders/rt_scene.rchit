#version 460
// The closest hit of a primary ray, triangles or spheres: the hit record's
// tag << 28 | custom index << 20 | geometry index << 16 | primitive << 8 |
// shadowed, where shadowed says whether a shadow ray straight up (+z, cull
// mask 0x02: the occluder alone, miss record 1) from the hit point is blocked.
#extension GL_EXT_ray_tracing : require

layout(set = 0, binding = 0) uniform accelerationStructureEXT scene;
layout(shaderRecordEXT, std430) buffer Record { uint tag; };
layout(location = 0) rayPayloadInEXT uint value;
layout(location = 1) rayPayloadEXT uint shadowed;

void main() {
    // The hit's built-ins are read before the shadow ray: lavapipe (Mesa 25.0)
    // returns the nested trace's instance and primitive after traceRayEXT.
    const uint hit = tag << 28 | uint(gl_InstanceCustomIndexEXT) << 20 | uint(gl_GeometryIndexEXT) << 16 |
                     uint(gl_PrimitiveID) << 8;
    const vec3 at = gl_WorldRayOriginEXT + gl_WorldRayDirectionEXT * gl_HitTEXT;
    shadowed = 1u;
    traceRayEXT(scene, gl_RayFlagsOpaqueEXT | gl_RayFlagsTerminateOnFirstHitEXT | gl_RayFlagsSkipClosestHitShaderEXT,
                0x02, 0, 0, 1, at, 0.001, vec3(0.0, 0.0, 1.0), 100.0, 1);
    value = hit | shadowed;
}
