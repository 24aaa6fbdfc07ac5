// tcnn-compatible Adam (see adam.h).
#include "engine/neural/adam.h"

#include <algorithm>
#include <cmath>
#include <thread>
#include <vector>

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

void Adam::step(NetworkWeights& w, const std::vector<float>& mlp_grad, const std::vector<float>& grid_grad,
                unsigned threads) {
    NBVH_CHECK(w.mlp.size() == mlp_m_.size() && mlp_grad.size() == mlp_m_.size());
    NBVH_CHECK(w.grid.size() == grid_m_.size() && grid_grad.size() == grid_m_.size());
    const float lr = lr_at_step(cfg_, steps_);
    const float inv_scale = 1.0f / cfg_.loss_scale;
    // Every counter is at most steps_ before this step, so t <= steps_ + 1 after it: the per-t table of
    // the bias-correction factors covers every t of this step.
    while (bias_sqrt_.size() < steps_ + 2) {
        const uint32_t ti = uint32_t(bias_sqrt_.size());
        bias_sqrt_.push_back(nb_adam_bias_sqrt(cfg_.beta2, ti));
        bias_div_.push_back(nb_adam_bias_div(cfg_.beta1, ti));
    }
    const float* bs = bias_sqrt_.data();
    const float* bd = bias_div_.data();
    const uint32_t nt = uint32_t(bias_sqrt_.size());
    const GpuAdamRule mlp_rule{lr, cfg_.beta1, cfg_.beta2, cfg_.epsilon, cfg_.l2_reg, 0u};
    const GpuAdamRule grid_rule{lr, cfg_.beta1, cfg_.beta2, cfg_.epsilon, cfg_.non_matrix_l2_reg,
                                cfg_.skip_zero_grad_non_matrix ? 1u : 0u};
    for (size_t i = 0; i < w.mlp.size(); ++i)
        nb_adam_update(w.mlp[i], mlp_m_[i], mlp_v_[i], mlp_t_[i], mlp_grad[i] * inv_scale, mlp_rule, bs, bd, nt);
    auto grid_slice = [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i)
            nb_adam_update(w.grid[i], grid_m_[i], grid_v_[i], grid_t_[i], grid_grad[i] * inv_scale, grid_rule, bs, bd,
                           nt);
    };
    const size_t n = w.grid.size();
    threads = unsigned(std::clamp<size_t>(threads, 1, std::max<size_t>(1, n / 65536)));
    if (threads == 1) {
        grid_slice(0, n);
    } else {
        std::vector<std::thread> pool;
        for (unsigned t = 1; t < threads; ++t) pool.emplace_back(grid_slice, n * t / threads, n * (t + 1) / threads);
        grid_slice(0, n / threads);
        for (std::thread& th : pool) th.join();
    }
    ++steps_;
}

} // namespace nbvh::neural
