// Lights sampled by next-event estimation (passes/shade.comp):
//   emissive triangles: selection proportional to power (luminance(emissive) * area) through a cdf built
//     on the CPU (engine/render/gpu_scene.cpp), then a uniform point on the triangle;
//   KHR_lights_punctual lights: selection proportional to their power (same file), then their one
//     direction (delta lights: no MIS, a BSDF sample never hits them).
// Layout of the light array and of light_cdf: shared/scene_gpu.h.
#ifndef NB_LIGHTS_GLSL
#define NB_LIGHTS_GLSL
#include "lib/bindings.glsl"
#include "lib/material.glsl"

// Area-measure pdf of any point on an emissive triangle with material m (selection x 1/area).
float nb_emissive_area_pdf(GpuMaterial m) {
    return params.light_total_power > 0.0f ? nb_luminance(m.emissive) / params.light_total_power : 0.0f;
}

// First i in [0, n) with light_cdf[base + i + 1] > u (that cdf has n + 1 entries, 0 .. 1).
uint nb_light_search(uint base, uint n, float u) {
    uint lo = 0u, hi = n - 1u;
    while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        if (light_cdf[base + mid + 1u] > u) hi = mid;
        else lo = mid + 1u;
    }
    return lo;
}

// Probabilities of the three next-event strategies: environment, emissive triangles, punctual lights,
// equal among those the scene has (they sum to 1, or are all 0 without any light). An environment of
// zero mean (none, or a black map: env_inv_mean 0) is no strategy, as a light count of 0 is none: a
// feature forced on where the scene lacks it (feature_set.h with_forced) leaves the image unchanged.
void nb_light_strategies(out float p_env, out float p_emissive, out float p_punctual) {
    float env = (NB_HAS_ENVIRONMENT && params.env_inv_mean > 0.0f && params.env_intensity > 0.0f) ? 1.0f : 0.0f;
    float emissive = (NB_HAS_EMISSION && params.light_count > 0u) ? 1.0f : 0.0f;
    float punctual = (NB_HAS_PUNCTUAL && params.punctual_count > 0u) ? 1.0f : 0.0f;
    float n = env + emissive + punctual;
    float inv = n > 0.0f ? 1.0f / n : 0.0f;
    p_env = env * inv;
    p_emissive = emissive * inv;
    p_punctual = punctual * inv;
}

// Samples a point on an emissive triangle as seen from p. Returns its radiance towards p; wi, dist
// and the solid-angle pdf (0: unusable sample).
// u0 picks the triangle (power cdf), u the point on it.
vec3 nb_emissive_sample(vec3 p, float u0, vec2 u, out vec3 wi, out float dist, out float pdf) {
    float u1 = u.x;
    float u2 = u.y;
    pdf = 0.0f;
    dist = 0.0f;
    wi = vec3(0.0f, 0.0f, 1.0f);
    GpuLight l = lights[nb_light_search(0u, params.light_count, u0)];
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
    float cos_signed = dot(nl / nl_len, wi);
    float cos_l = abs(cos_signed);
    if (cos_l < 1.0e-6f) return vec3(0.0f);
    // A single-sided emitter seen from behind: a BSDF ray would pass through its culled back face.
    if (l.side * cos_signed > 0.0f) return vec3(0.0f);
    GpuTriangle tri = triangles[l.triangle];
    GpuMaterial m = materials[tri.material];
    pdf = nb_emissive_area_pdf(m) * d2 / cos_l;
    return nb_triangle_emission(m, tri, vec2(b1, b2));
}

// Samples a punctual light as seen from p: returns the radiance-like term Le such that the reflected
// radiance is f(wo, wi) cos(theta_i) Le / pdf (point/spot: colour x intensity / d^2 x cone x range window;
// directional: colour x illuminance); wi, dist (NB_INF: directional) and pdf, the discrete probability of
// choosing this light (0: unusable sample). Range window and cone: KHR_lights_punctual's recommended ones.
vec3 nb_punctual_sample(vec3 p, float u, out vec3 wi, out float dist, out float pdf) {
    pdf = 0.0f;
    dist = NB_INF;
    wi = vec3(0.0f, 0.0f, 1.0f);
    uint base = params.light_count + 1u; // the punctual cdf follows the emissive one
    uint k = nb_light_search(base, params.punctual_count, u);
    GpuLight l = lights[params.light_count + k];
    float select = light_cdf[base + k + 1u] - light_cdf[base + k];
    if (!(select > 0.0f)) return vec3(0.0f);
    if (l.kind == NB_LIGHT_DIRECTIONAL) {
        wi = -l.p1;
        pdf = select;
        return l.p2;
    }
    vec3 d = l.p0 - p;
    float d2 = dot(d, d);
    if (!(d2 > 0.0f)) return vec3(0.0f);
    dist = sqrt(d2);
    wi = d / dist;
    float falloff = 1.0f / d2;
    if (l.area > 0.0f) { // range: (1 - (d / range)^4)^2 window, zero beyond the range
        float r = dist / l.area;
        float w = clamp(1.0f - r * r * r * r, 0.0f, 1.0f);
        falloff *= w * w;
    }
    float cone = clamp(dot(l.p1, -wi) * l.spot_scale + l.spot_offset, 0.0f, 1.0f);
    falloff *= cone * cone;
    if (!(falloff > 0.0f)) return vec3(0.0f);
    pdf = select;
    return l.p2 * falloff;
}

#endif
