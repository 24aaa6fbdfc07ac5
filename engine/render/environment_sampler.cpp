#include "engine/render/environment_sampler.h"

#include <algorithm>
#include <cmath>

#include "shaders/shared/sampling.h"

namespace nbvh::render {

namespace {
float clean(float v) { return std::isfinite(v) && v > 0.0f ? v : 0.0f; }

// 2x2 box averages (an odd last row or column is averaged with itself), clean values.
std::vector<float> halve(const std::vector<float>& rgb, uint32_t& w, uint32_t& h) {
    const uint32_t hw = std::max(1u, w / 2), hh = std::max(1u, h / 2);
    std::vector<float> out(size_t(hw) * hh * 3, 0.0f);
    for (uint32_t y = 0; y < hh; ++y)
        for (uint32_t x = 0; x < hw; ++x)
            for (int c = 0; c < 3; ++c) {
                float sum = 0.0f;
                for (uint32_t dy = 0; dy < 2; ++dy)
                    for (uint32_t dx = 0; dx < 2; ++dx) {
                        const uint32_t sx = std::min(w - 1, 2 * x + dx), sy = std::min(h - 1, 2 * y + dy);
                        sum += clean(rgb[(size_t(sy) * w + sx) * 3 + c]);
                    }
                out[(size_t(y) * hw + x) * 3 + c] = 0.25f * sum;
            }
    w = hw;
    h = hh;
    return out;
}
} // namespace

uint64_t environment_table_bytes(uint32_t w, uint32_t h) {
    const uint64_t texels = uint64_t(w) * h;
    return (texels * 4 + (h + 1) + uint64_t(h) * (w + 1) + texels + 3) / 4 * 16;
}

EnvironmentTable build_environment_table(const Environment& env, uint64_t max_bytes) {
    EnvironmentTable t;
    t.intensity = std::isfinite(env.intensity) ? std::max(env.intensity, 0.0f) : 0.0f;
    t.rotation = std::isfinite(env.rotation) ? env.rotation : 0.0f;
    const bool map = !env.rgb.empty() && env.width > 0 && env.height > 0 &&
                     env.rgb.size() >= size_t(env.width) * env.height * 3;
    t.width = map ? env.width : 1;
    t.height = map ? env.height : 1;
    std::vector<float> halved; // the map after halvings (empty: env.rgb as it is)
    while (map && environment_table_bytes(t.width, t.height) > max_bytes && (t.width > 1 || t.height > 1)) {
        halved = halve(halved.empty() ? env.rgb : halved, t.width, t.height);
        t.halvings++;
    }
    const std::vector<float>& rgb = halved.empty() ? env.rgb : halved;
    const uint32_t w = t.width, h = t.height;
    const size_t texels = size_t(w) * h;
    t.data.assign(texels * 4 + (h + 1) + size_t(h) * (w + 1) + texels, 0.0f);
    for (size_t i = 0; i < texels; ++i) // rgba: one 16-byte load per texel in the shader (a unused)
        for (int c = 0; c < 3; ++c) t.data[i * 4 + c] = clean(map ? rgb[i * 3 + c] : env.constant[c]);

    // The shader reads the map bilinearly (texel centres at half-integers, u wraps, v clamps), so a texel's
    // share of the samples follows the mean of that bilinear function over the texel: its luminance and
    // its 8 neighbours' with weights (1/8, 3/4, 1/8) per axis (pbrt-v4 builds its image light's
    // distribution from the bilinear lookup the same way). Sampling only with the texels' own values
    // would leave a bright texel's neighbours, which the bilinear lookup lights up to half of it, with a
    // small density: fireflies.
    std::vector<float> lum(texels);
    for (size_t i = 0; i < texels; ++i) {
        const float* p = t.data.data() + i * 4;
        lum[i] = nb_luminance(vec3(p[0], p[1], p[2]));
    }
    const float wk[3] = {0.125f, 0.75f, 0.125f};
    auto filtered = [&](uint32_t x, uint32_t y) {
        double s = 0.0;
        for (int j = -1; j <= 1; ++j) {
            const uint32_t yy = uint32_t(std::clamp(int(y) + j, 0, int(h) - 1));
            for (int i = -1; i <= 1; ++i) {
                const uint32_t xx = uint32_t((int(x) + i + int(w)) % int(w));
                s += double(wk[i + 1] * wk[j + 1]) * double(lum[size_t(yy) * w + xx]);
            }
        }
        return s;
    };

    // f = filtered luminance * sin(theta) at row centres; rows in double for long sums.
    float* marginal = t.data.data() + texels * 4;
    float* conditional = marginal + (h + 1);
    float* density = conditional + size_t(h) * (w + 1);
    std::vector<double> row_sum(h, 0.0), f(texels, 0.0);
    double total = 0.0;
    for (uint32_t y = 0; y < h; ++y) {
        const double sin_theta = std::sin(NB_PI * (float(y) + 0.5f) / float(h));
        float* cdf = conditional + size_t(y) * (w + 1);
        double acc = 0.0;
        cdf[0] = 0.0f;
        for (uint32_t x = 0; x < w; ++x) {
            f[size_t(y) * w + x] = filtered(x, y) * sin_theta;
            acc += f[size_t(y) * w + x];
            cdf[x + 1] = float(acc);
        }
        for (uint32_t x = 1; x <= w; ++x) cdf[x] = acc > 0.0 ? float(cdf[x] / acc) : float(x) / float(w);
        cdf[w] = 1.0f;
        row_sum[y] = acc;
        total += acc;
    }
    marginal[0] = 0.0f;
    double acc = 0.0;
    for (uint32_t y = 0; y < h; ++y) {
        acc += row_sum[y];
        marginal[y + 1] = total > 0.0 ? float(acc / total) : float(y + 1) / float(h);
    }
    marginal[h] = 1.0f;
    t.inv_mean = total > 0.0 ? float(double(texels) / total) : 0.0f;
    // Density in (u, v) of each texel (f / mean f): what the shader's pdf reads (nb_env_texel_density).
    for (size_t i = 0; i < texels; ++i) density[i] = float(f[i] * double(t.inv_mean));
    t.data.resize((t.data.size() + 3) / 4 * 4, 0.0f); // whole vec4s (the shader's array)
    return t;
}

float environment_density(const EnvironmentTable& t, uint32_t x, uint32_t y) {
    const size_t texels = size_t(t.width) * t.height;
    return t.data[texels * 4 + (t.height + 1) + size_t(t.height) * (t.width + 1) + size_t(y) * t.width + x];
}

} // namespace nbvh::render
