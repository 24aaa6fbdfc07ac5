// Emissive-triangle lights: selection proportional to power (luminance(emissive) * area) through a
// cdf built on the CPU (engine/render/gpu_scene.cpp), then a uniform point on the triangle.
#ifndef NB_LIGHTS_GLSL
#define NB_LIGHTS_GLSL
#include "lib/bindings.glsl"
#include "lib/material.glsl"

// Area-measure pdf of any point on an emissive triangle with material m (selection x 1/area).
float nb_emissive_area_pdf(GpuMaterial m) {
    return params.light_total_power > 0.0f ? nb_luminance(m.emissive) / params.light_total_power : 0.0f;
}

uint nb_light_search(float u) {
    uint lo = 0u, hi = params.light_count - 1u;
    while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        if (light_cdf[mid + 1u] > u) hi = mid;
        else lo = mid + 1u;
    }
    return lo;
}

// Samples a point on an emissive triangle as seen from p. Returns its radiance towards p; wi, dist
// and the solid-angle pdf (0: unusable sample).
vec3 nb_emissive_sample(vec3 p, inout uint rng, out vec3 wi, out float dist, out float pdf) {
    float u0 = nb_rng_next(rng);
    float u1 = nb_rng_next(rng);
    float u2 = nb_rng_next(rng);
    pdf = 0.0f;
    dist = 0.0f;
    wi = vec3(0.0f, 0.0f, 1.0f);
    GpuLight l = lights[nb_light_search(u0)];
    float su = sqrt(u1);
    float b1 = u2 * su;          // weight of p1
    float b2 = 1.0f - su;        // weight of p2
    vec3 q = (1.0f - b1 - b2) * l.p0 + b1 * l.p1 + b2 * l.p2;
    vec3 d = q - p;
    float d2 = dot(d, d);
    if (!(d2 > 0.0f)) return vec3(0.0f);
    dist = sqrt(d2);
    wi = d / dist;
    vec3 nl = cross(l.p1 - l.p0, l.p2 - l.p0);
    float nl_len = length(nl);
    if (!(nl_len > 0.0f)) return vec3(0.0f);
    float cos_l = abs(dot(nl / nl_len, wi));
    if (cos_l < 1.0e-6f) return vec3(0.0f);
    GpuTriangle tri = triangles[l.triangle];
    GpuMaterial m = materials[tri.material];
    pdf = nb_emissive_area_pdf(m) * d2 / cos_l;
    return nb_triangle_emission(m, tri, vec2(b1, b2));
}

#endif
