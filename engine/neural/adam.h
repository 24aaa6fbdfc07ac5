// Adam with tiny-cuda-nn semantics (notes tiny-cuda-nn §C.2, official notes §5) on the CPU: fp32 master
// weights, fp32 first/second moments and a uint32 step counter PER PARAMETER. The per-parameter update
// (moments, folded bias correction, l2, the skip of zero grid gradients) is nb_adam_update of
// engine/neural/shared/adam_update.h, shared with the CUDA trainer; this class owns the state, divides
// the gradients by loss_scale (g = grad / loss_scale) and applies the update with
//   grid (non-matrix) params: exactly zero g skipped (sparse/lazy); l2 = non_matrix_l2_reg
//   MLP (matrix) params: always updated; l2 = l2_reg
// AdaBound, weight clipping and relative/absolute decay are tcnn options N-BVH leaves off; they
// are not implemented. The learning rate comes from ExponentialDecay (lr_at_step), N-BVH defaults.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/neural/reference_network.h"
#include "engine/neural/shared/adam_update.h"

namespace nbvh::neural {

struct AdamConfig {
    float learning_rate = 1e-2f;
    float beta1 = 0.9f;
    float beta2 = 0.999f;
    float epsilon = 1e-8f;
    float l2_reg = 1e-8f;          // MLP weights
    float non_matrix_l2_reg = 0.0f; // grid
    float loss_scale = 1.0f;        // gradients are divided by this (tcnn fp16 training uses 128)
    bool skip_zero_grad_non_matrix = true;
    // ExponentialDecay (tcnn exponential_decay.h): lr(s) = lr * base^(floor((min(s,end)-start)/interval)+1)
    // for s >= start (s = 0-based index of the step about to be taken), else lr.
    uint32_t decay_start = 10000;
    uint32_t decay_interval = 2000;
    uint32_t decay_end = 10000000;
    float decay_base = 0.33f;
};

// Effective learning rate of 0-based step s under the config's ExponentialDecay.
float lr_at_step(const AdamConfig& cfg, uint64_t step);

class Adam {
public:
    Adam(const AdamConfig& cfg, size_t mlp_params, size_t grid_params);
    // One step on w (fp32 master) with dense gradients of the same sizes as w.mlp / w.grid.
    // `threads` > 1 splits the grid update into contiguous slices (per-parameter independent, so the
    // result is identical for any thread count).
    void step(NetworkWeights& w, const std::vector<float>& mlp_grad, const std::vector<float>& grid_grad,
              unsigned threads = 1);
    uint64_t steps_taken() const { return steps_; }
    const AdamConfig& config() const { return cfg_; }
    // State, exposed for tests and checkpoints: moments and per-parameter step counters.
    const std::vector<float>& mlp_m() const { return mlp_m_; }
    const std::vector<float>& mlp_v() const { return mlp_v_; }
    const std::vector<uint32_t>& mlp_t() const { return mlp_t_; }
    const std::vector<float>& grid_m() const { return grid_m_; }
    const std::vector<float>& grid_v() const { return grid_v_; }
    const std::vector<uint32_t>& grid_t() const { return grid_t_; }

private:
    AdamConfig cfg_;
    uint64_t steps_ = 0;
    std::vector<float> mlp_m_, mlp_v_, grid_m_, grid_v_;
    std::vector<uint32_t> mlp_t_, grid_t_;
    // Bias-correction factors by per-parameter step t (nb_adam_bias_sqrt / nb_adam_bias_div), computed
    // once per t instead of two powf per parameter and step; identical values.
    std::vector<float> bias_sqrt_, bias_div_;
};

} // namespace nbvh::neural
