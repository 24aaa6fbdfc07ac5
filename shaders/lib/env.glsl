// Environment lookups and importance sampling (piecewise-constant over texels, density proportional
// to luminance * sin(theta); pbrt-v4 §12.6). Buffer layout: bindings.glsl (NB_BIND_ENV).
#ifndef NB_ENV_GLSL
#define NB_ENV_GLSL
#include "lib/bindings.glsl"
#include "shared/sampling.h"

vec3 nb_env_texel(uint x, uint y) {
    uint i = (y * params.env_width + x) * 3u;
    return vec3(env_data[i], env_data[i + 1u], env_data[i + 2u]);
}

uint nb_env_marginal_base() { return params.env_width * params.env_height * 3u; }
uint nb_env_conditional_base(uint row) {
    return nb_env_marginal_base() + params.env_height + 1u + row * (params.env_width + 1u);
}

// Density in (u, v) of texel (x, y): f / mean(f).
float nb_env_texel_density(uint x, uint y) {
    float sin_theta = sin(NB_PI * (float(y) + 0.5f) / float(params.env_height));
    return nb_luminance(nb_env_texel(x, y)) * sin_theta * params.env_inv_mean;
}

void nb_env_texel_of(vec3 dir, out uint x, out uint y, out float sin_theta) {
    vec2 uv = nb_env_dir_to_uv(dir, params.env_rotation);
    x = min(uint(uv.x * float(params.env_width)), params.env_width - 1u);
    y = min(uint(uv.y * float(params.env_height)), params.env_height - 1u);
    sin_theta = sin(uv.y * NB_PI);
}

vec3 nb_env_radiance(vec3 dir) {
    uint x, y;
    float st;
    nb_env_texel_of(dir, x, y, st);
    return nb_env_texel(x, y) * params.env_intensity;
}

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
        if (env_data[base + mid + 1u] > u) hi = mid;
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
    float c0 = env_data[mb + y], c1 = env_data[mb + y + 1u];
    float dv = c1 > c0 ? clamp((u1 - c0) / (c1 - c0), 0.0f, 1.0f) : 0.5f;
    uint cb = nb_env_conditional_base(y);
    uint x = nb_env_search(cb, params.env_width, u2);
    float d0 = env_data[cb + x], d1 = env_data[cb + x + 1u];
    float du = d1 > d0 ? clamp((u2 - d0) / (d1 - d0), 0.0f, 1.0f) : 0.5f;
    vec2 uv = vec2((float(x) + du) / float(params.env_width), (float(y) + dv) / float(params.env_height));
    dir = nb_env_uv_to_dir(uv, params.env_rotation);
    float sin_theta = sin(uv.y * NB_PI);
    pdf = sin_theta > 1.0e-6f ? nb_env_texel_density(x, y) / (2.0f * NB_PI * NB_PI * sin_theta) : 0.0f;
    return nb_env_texel(x, y) * params.env_intensity;
}

#endif
