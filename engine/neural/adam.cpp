// tcnn-compatible Adam (see adam.h).
#include "engine/neural/adam.h"

#include <algorithm>
#include <cmath>

#include "engine/core/error.h"

namespace nbvh::neural {

float lr_at_step(const AdamConfig& cfg, uint64_t step) {
    if (step < cfg.decay_start || cfg.decay_interval == 0) return cfg.learning_rate;
    const uint64_t s = std::min<uint64_t>(step, cfg.decay_end);
    if (s < cfg.decay_start) return cfg.learning_rate;
    const uint64_t k = (s - cfg.decay_start) / cfg.decay_interval + 1;
    return cfg.learning_rate * std::pow(cfg.decay_base, float(k));
}

Adam::Adam(const AdamConfig& cfg, size_t mlp_params, size_t grid_params)
    : cfg_(cfg), mlp_m_(mlp_params, 0.0f), mlp_v_(mlp_params, 0.0f), grid_m_(grid_params, 0.0f),
      grid_v_(grid_params, 0.0f), mlp_t_(mlp_params, 0u), grid_t_(grid_params, 0u) {}

namespace {
// One parameter's update; returns false when skipped.
inline void adam_update(float& w, float g, float& m, float& v, uint32_t& t, float l2, float lr, const AdamConfig& c) {
    g += l2 * w;
    m = c.beta1 * m + (1.0f - c.beta1) * g;
    v = c.beta2 * v + (1.0f - c.beta2) * g * g;
    const uint32_t ti = ++t;
    const float lr_t = lr * std::sqrt(1.0f - std::pow(c.beta2, float(ti))) / (1.0f - std::pow(c.beta1, float(ti)));
    w -= lr_t / (std::sqrt(v) + c.epsilon) * m;
}
} // namespace

void Adam::step(NetworkWeights& w, const std::vector<float>& mlp_grad, const std::vector<float>& grid_grad) {
    NBVH_CHECK(w.mlp.size() == mlp_m_.size() && mlp_grad.size() == mlp_m_.size());
    NBVH_CHECK(w.grid.size() == grid_m_.size() && grid_grad.size() == grid_m_.size());
    const float lr = lr_at_step(cfg_, steps_);
    const float inv_scale = 1.0f / cfg_.loss_scale;
    for (size_t i = 0; i < w.mlp.size(); ++i)
        adam_update(w.mlp[i], mlp_grad[i] * inv_scale, mlp_m_[i], mlp_v_[i], mlp_t_[i], cfg_.l2_reg, lr, cfg_);
    for (size_t i = 0; i < w.grid.size(); ++i) {
        const float g = grid_grad[i] * inv_scale;
        if (g == 0.0f && cfg_.skip_zero_grad_non_matrix) continue;
        adam_update(w.grid[i], g, grid_m_[i], grid_v_[i], grid_t_[i], cfg_.non_matrix_l2_reg, lr, cfg_);
    }
    ++steps_;
}

} // namespace nbvh::neural
