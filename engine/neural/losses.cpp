// The composite N-BVH loss (see losses.h).
#include "engine/neural/losses.h"

#include <algorithm>
#include <cmath>

#include "engine/core/error.h"

namespace nbvh::neural {

GpuLossConfig to_gpu(const LossConfig& cfg) {
    return GpuLossConfig{cfg.w_visibility, cfg.w_depth, cfg.w_normal, cfg.w_albedo, cfg.normal_linear ? 1u : 0u,
                         cfg.visibility_masking ? 1u : 0u};
}

float composite_loss(const Outputs& y, const Targets& t, const LossConfig& cfg, Outputs* dl_dy,
                     std::array<float, NB_MLP_OUTPUTS>* per_slot) {
    for (uint32_t i = 0; i < NB_MLP_OUTPUTS; ++i) NBVH_CHECK(std::isfinite(y[i]) && std::isfinite(t[i]));
    const GpuLossConfig c = to_gpu(cfg);
    std::array<float, NB_MLP_OUTPUTS> value{};
    Outputs g{};
    const float total = nb_composite_loss(y.data(), t.data(), c, value.data(), g.data());
    if (dl_dy) *dl_dy = g;
    if (per_slot)
        for (uint32_t i = 0; i < NB_MLP_OUTPUTS; ++i) (*per_slot)[i] = nb_loss_weight(c, i) * value[i];
    return total;
}

Targets make_targets(bool hit, float depth_u, vec3 n, vec3 albedo, float visibility) {
    Targets t{};
    if (!hit) return t;
    t[NB_OUT_VISIBILITY] = visibility;
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
