#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
// examples/raytrace: a primary ray's closest hit. The normal is interpolated
// as the rasterising paths interpolate theirs (raytrace_scene.glsl's
// transform: each vertex's normal by mat3(world), then weighted by the
// barycentrics), the shading is theirs (raytrace_shading.glsl), and with
// shadows on, a ray towards the light decides whether it is visible.
#include "raytrace_shading.glsl"
#include "raytrace_trace.glsl"

// main.cpp's InstanceRecord, at the instance's custom index.
struct Instance {
    mat4 world;
    vec4 colour;
    uint first_index;  // of its mesh, in indices
    int vertex_offset;
};
layout(set = 0, binding = 2, std430) readonly buffer Instances { Instance instances[]; };
layout(set = 0, binding = 3, std430) readonly buffer Indices { uint indices[]; };
layout(set = 0, binding = 4, std430) readonly buffer Normals { float normals[]; };

hitAttributeEXT vec2 barycentrics;
layout(location = primary) rayPayloadInEXT vec3 colour;
layout(location = shadow) rayPayloadEXT float light_visible;

vec3 world_normal(mat4 world, int vertex) {
    return mat3(world) * vec3(normals[3 * vertex], normals[3 * vertex + 1], normals[3 * vertex + 2]);
}

void main() {
    // Every built-in is read before the shadow ray: lavapipe (Mesa 25.0)
    // returns the nested trace's after traceRayEXT.
    const Instance hit = instances[gl_InstanceCustomIndexEXT];
    const uint first = hit.first_index + 3u * uint(gl_PrimitiveID);
    const vec3 weights = vec3(1.0 - barycentrics.x - barycentrics.y, barycentrics.x, barycentrics.y);
    vec3 normal = vec3(0.0);
    for (uint i = 0u; i < 3u; ++i) normal += weights[i] * world_normal(hit.world, hit.vertex_offset + int(indices[first + i]));
    const vec3 at = gl_WorldRayOriginEXT + gl_WorldRayDirectionEXT * gl_HitTEXT;
    const vec3 towards_light = trace.light_direction.xyz;
    light_visible = 1.0;
    // Facing away, the light adds nothing whether blocked or not.
    if (trace.shadows != 0u && dot(normal, towards_light) > 0.0) {
        light_visible = 0.0;  // unless the lit miss shader runs
        // tmin: past the surface's own triangle, whose hit point is off by
        // rounding (scene coordinates of tens of units, float).
        traceRayEXT(scene, gl_RayFlagsOpaqueEXT | gl_RayFlagsTerminateOnFirstHitEXT | gl_RayFlagsSkipClosestHitShaderEXT,
                    0xff, 0, 0, shadow, at, 1e-3, towards_light, 1000.0, shadow);
    }
    colour = shade(normal, hit.colour.rgb, towards_light, light_visible);
}
