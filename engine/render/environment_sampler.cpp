#include "engine/render/environment_sampler.h"

#include <cmath>

#include "shaders/shared/sampling.h"

namespace nbvh::render {

namespace {
float clean(float v) { return std::isfinite(v) && v > 0.0f ? v : 0.0f; }
} // namespace

EnvironmentTable build_environment_table(const Environment& env) {
    EnvironmentTable t;
    t.intensity = std::isfinite(env.intensity) ? std::max(env.intensity, 0.0f) : 0.0f;
    t.rotation = std::isfinite(env.rotation) ? env.rotation : 0.0f;
    const bool map = !env.rgb.empty() && env.width > 0 && env.height > 0 &&
                     env.rgb.size() >= size_t(env.width) * env.height * 3;
    t.width = map ? env.width : 1;
    t.height = map ? env.height : 1;
    const uint32_t w = t.width, h = t.height;
    const size_t texels = size_t(w) * h;
    t.data.assign(texels * 3 + (h + 1) + size_t(h) * (w + 1), 0.0f);
    for (size_t i = 0; i < texels; ++i)
        for (int c = 0; c < 3; ++c) t.data[i * 3 + c] = clean(map ? env.rgb[i * 3 + c] : env.constant[c]);

    // f = luminance * sin(theta) at row centres; rows in double for long sums.
    float* marginal = t.data.data() + texels * 3;
    float* conditional = marginal + (h + 1);
    std::vector<double> row_sum(h, 0.0);
    double total = 0.0;
    for (uint32_t y = 0; y < h; ++y) {
        const float sin_theta = std::sin(NB_PI * (float(y) + 0.5f) / float(h));
        float* cdf = conditional + size_t(y) * (w + 1);
        double acc = 0.0;
        cdf[0] = 0.0f;
        for (uint32_t x = 0; x < w; ++x) {
            const float* p = t.data.data() + (size_t(y) * w + x) * 3;
            acc += double(nb_luminance(vec3(p[0], p[1], p[2])) * sin_theta);
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
    return t;
}

float environment_density(const EnvironmentTable& t, uint32_t x, uint32_t y) {
    const float* p = t.data.data() + (size_t(y) * t.width + x) * 3;
    const float sin_theta = std::sin(NB_PI * (float(y) + 0.5f) / float(t.height));
    return nb_luminance(vec3(p[0], p[1], p[2])) * sin_theta * t.inv_mean;
}

} // namespace nbvh::render
