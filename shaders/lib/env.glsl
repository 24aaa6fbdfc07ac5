// Environment lookups and importance sampling (pbrt-v4 §12.6). Radiance is read bilinearly (texel centres
// at half-integers, u wraps, v clamps): a sky or map seen directly has no texel steps. Directions are drawn
// piecewise-constant over texels, with densities the CPU built from each texel's mean of that bilinear
// luminance * sin(theta) (engine/render/environment_sampler.cpp); the pdf is that of the sampling
// procedure, so NEE and MIS stay unbiased with the filtered radiance. Buffer layout: rgba texels, marginal
// cdf, conditional cdfs, densities (bindings.glsl NB_BIND_ENV).
#ifndef NB_ENV_GLSL
#define NB_ENV_GLSL
#include "lib/bindings.glsl"
#include "shared/sampling.h"

vec3 nb_env_texel(uint x, uint y) { return env_data[y * params.env_width + x].xyz; }

// Float i of the buffer (the cdfs and densities after the texels).
float nb_env_float(uint i) { return env_data[i >> 2u][i & 3u]; }

uint nb_env_marginal_base() { return params.env_width * params.env_height * 4u; }
uint nb_env_conditional_base(uint row) {
    return nb_env_marginal_base() + params.env_height + 1u + row * (params.env_width + 1u);
}

uint nb_env_density_base() { return nb_env_conditional_base(params.env_height); }

// Density in (u, v) of texel (x, y): f / mean(f), precomputed.
float nb_env_texel_density(uint x, uint y) { return nb_env_float(nb_env_density_base() + y * params.env_width + x); }

// Bilinear radiance at (u, v) in [0, 1]^2 (before the intensity; footprint: shared/sampling.h).
vec3 nb_env_bilinear(vec2 uv) {
    uvec2 lo, hi;
    vec2 f;
    nb_env_bilinear_footprint(uv, params.env_width, params.env_height, lo, hi, f);
    vec3 top = mix(nb_env_texel(lo.x, lo.y), nb_env_texel(hi.x, lo.y), f.x);
    vec3 bottom = mix(nb_env_texel(lo.x, hi.y), nb_env_texel(hi.x, hi.y), f.x);
    return mix(top, bottom, f.y);
}

void nb_env_texel_of(vec3 dir, out uint x, out uint y, out float sin_theta) {
    vec2 uv = nb_env_dir_to_uv(dir, params.env_rotation);
    x = min(uint(uv.x * float(params.env_width)), params.env_width - 1u);
    y = min(uint(uv.y * float(params.env_height)), params.env_height - 1u);
    sin_theta = sin(uv.y * NB_PI);
}

vec3 nb_env_radiance(vec3 dir) { return nb_env_bilinear(nb_env_dir_to_uv(dir, params.env_rotation)) * params.env_intensity; }

// Solid-angle pdf of nb_env_sample producing dir.
float nb_env_pdf(vec3 dir) {
    uint x, y;
    float sin_theta;
    nb_env_texel_of(dir, x, y, sin_theta);
    if (sin_theta <= 0.0f) return 0.0f;
    return nb_env_texel_density(x, y) / (2.0f * NB_PI * NB_PI * sin_theta);
}

// First index i in [0, n) with cdf[base + i + 1] > u (cdf has n + 1 entries, cdf[0] = 0, cdf[n] = 1).
uint nb_env_search(uint base, uint n, float u) {
    uint lo = 0u, hi = n - 1u;
    while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        if (nb_env_float(base + mid + 1u) > u) hi = mid;
        else lo = mid + 1u;
    }
    return lo;
}

// Samples a direction; returns the radiance and solid-angle pdf (0 when the sample is unusable).
vec3 nb_env_sample(vec2 u, out vec3 dir, out float pdf) {
    float u1 = u.x;
    float u2 = u.y;
    uint mb = nb_env_marginal_base();
    uint y = nb_env_search(mb, params.env_height, u1);
    float c0 = nb_env_float(mb + y), c1 = nb_env_float(mb + y + 1u);
    float dv = c1 > c0 ? clamp((u1 - c0) / (c1 - c0), 0.0f, 1.0f) : 0.5f;
    uint cb = nb_env_conditional_base(y);
    uint x = nb_env_search(cb, params.env_width, u2);
    float d0 = nb_env_float(cb + x), d1 = nb_env_float(cb + x + 1u);
    float du = d1 > d0 ? clamp((u2 - d0) / (d1 - d0), 0.0f, 1.0f) : 0.5f;
    vec2 uv = vec2((float(x) + du) / float(params.env_width), (float(y) + dv) / float(params.env_height));
    dir = nb_env_uv_to_dir(uv, params.env_rotation);
    float sin_theta = sin(uv.y * NB_PI);
    pdf = sin_theta > 1.0e-6f ? nb_env_texel_density(x, y) / (2.0f * NB_PI * NB_PI * sin_theta) : 0.0f;
    return nb_env_bilinear(uv) * params.env_intensity;
}

#endif
