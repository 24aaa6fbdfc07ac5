// The composite N-BVH loss (see losses.h).
#include "engine/neural/losses.h"

#include <algorithm>
#include <cmath>

#include "engine/core/error.h"

namespace nbvh::neural {
namespace {
float sgn(float x) { return x > 0.0f ? 1.0f : (x < 0.0f ? -1.0f : 0.0f); }
} // namespace

float composite_loss(const Outputs& y, const Targets& t, const LossConfig& cfg, Outputs* dl_dy,
                     std::array<float, NB_MLP_OUTPUTS>* per_slot) {
    for (uint32_t i = 0; i < NB_MLP_OUTPUTS; ++i) NBVH_CHECK(std::isfinite(y[i]) && std::isfinite(t[i]));
    std::array<float, NB_MLP_OUTPUTS> l{};
    Outputs g{};
    // Visibility: BCE on the clamped prediction.
    {
        const float p = std::clamp(y[NB_OUT_VISIBILITY], NB_BCE_CLAMP, 1.0f - NB_BCE_CLAMP);
        const float tv = t[NB_OUT_VISIBILITY];
        l[NB_OUT_VISIBILITY] = cfg.w_visibility * -(tv * std::log(p) + (1.0f - tv) * std::log(1.0f - p));
        g[NB_OUT_VISIBILITY] = cfg.w_visibility * -(tv - p) / (p - p * p);
    }
    const bool masked = cfg.visibility_masking && t[NB_OUT_VISIBILITY] < 0.5f;
    if (!masked) {
        const float dd = y[NB_OUT_DEPTH] - t[NB_OUT_DEPTH];
        l[NB_OUT_DEPTH] = cfg.w_depth * std::fabs(dd);
        g[NB_OUT_DEPTH] = cfg.w_depth * sgn(dd);
        for (uint32_t i = NB_OUT_NORMAL; i < NB_OUT_NORMAL + 3; ++i) {
            const float s = cfg.normal_linear ? NB_NORMAL_LINEAR_SCALE : 1.0f;
            const float o = cfg.normal_linear ? NB_NORMAL_LINEAR_OFFSET : 0.0f;
            const float d = s * y[i] - o - t[i];
            l[i] = cfg.w_normal * std::fabs(d);
            g[i] = cfg.w_normal * s * sgn(d);
        }
        for (uint32_t i = NB_OUT_ALBEDO; i < NB_OUT_ALBEDO + 3; ++i) {
            const float d = y[i] - t[i];
            const float den = y[i] * y[i] + NB_REL_L2_EPS;
            l[i] = cfg.w_albedo * d * d / den;
            g[i] = cfg.w_albedo * 2.0f * d / den;
        }
    }
    float total = 0.0f;
    for (float v : l) total += v;
    if (dl_dy) *dl_dy = g;
    if (per_slot) *per_slot = l;
    return total;
}

Targets make_targets(bool hit, float depth_u, vec3 n, vec3 albedo) {
    Targets t{};
    if (!hit) return t;
    t[NB_OUT_VISIBILITY] = 1.0f;
    t[NB_OUT_DEPTH] = std::clamp(depth_u, 0.0f, 1.0f);
    t[NB_OUT_NORMAL + 0] = (n.x + 1.0f) * 0.5f;
    t[NB_OUT_NORMAL + 1] = (n.y + 1.0f) * 0.5f;
    t[NB_OUT_NORMAL + 2] = (n.z + 1.0f) * 0.5f;
    t[NB_OUT_ALBEDO + 0] = albedo.x;
    t[NB_OUT_ALBEDO + 1] = albedo.y;
    t[NB_OUT_ALBEDO + 2] = albedo.z;
    return t;
}

} // namespace nbvh::neural
