// CPU side of environment importance sampling: the piecewise-constant 2D distribution over texels with
// density proportional to the texel's mean of the bilinearly filtered luminance * sin(theta) (pbrt-v4
// §12.6), packed the way shaders/lib/env.glsl reads it: rgba texels (w*h*4), marginal row cdf (h+1),
// conditional cdfs (h*(w+1)), per-texel densities in (u, v) (w*h).
#pragma once
#include <cstdint>
#include <vector>

#include "engine/scene/scene.h"

namespace nbvh::render {

struct EnvironmentTable {
    uint32_t width = 1, height = 1;
    std::vector<float> data;   // the buffer uploaded to NB_BIND_ENV
    float inv_mean = 0.0f;     // 1 / mean(f): f(texel) * inv_mean is the density in (u, v)
    float intensity = 1.0f;
    float rotation = 0.0f;
    uint32_t halvings = 0;     // times the map was halved to fit max_bytes
};

// Bytes of the table of a w x h map (rgba texels, cdfs, densities, padded to whole vec4s).
uint64_t environment_table_bytes(uint32_t w, uint32_t h);

// A constant environment becomes a 1x1 map. Non-finite or negative texels are read as 0. A map whose table
// would exceed `max_bytes` (one storage binding) is halved (2x2 box averages) until it fits.
EnvironmentTable build_environment_table(const Environment& env, uint64_t max_bytes = UINT64_MAX);

// Density in (u, v) of texel (x, y): the value the shader's nb_env_texel_density reads.
float environment_density(const EnvironmentTable& table, uint32_t x, uint32_t y);

} // namespace nbvh::render
