// examples/raytrace: the shading every render path uses, so that a path's
// image differs from the rasterised one only by what it finds visible and
// the normal it interpolates. Lambert, one directional light, an ambient
// floor. A ray-traced path passes light_visible 0 where its shadow ray is
// blocked; the rasterising paths have no shadows and pass 1.
const float ambient = 0.2;

vec3 shade(vec3 normal, vec3 albedo, vec3 towards_light, float light_visible) {
    const float diffuse = max(dot(normalize(normal), towards_light), 0.0) * light_visible;
    return albedo * (ambient + (1.0 - ambient) * diffuse);
}
