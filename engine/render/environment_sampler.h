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
};

// A constant environment becomes a 1x1 map. Non-finite or negative texels are read as 0.
EnvironmentTable build_environment_table(const Environment& env);

// Density in (u, v) of texel (x, y): the value the shader's nb_env_texel_density reads.
float environment_density(const EnvironmentTable& table, uint32_t x, uint32_t y);

} // namespace nbvh::render
