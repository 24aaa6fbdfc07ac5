// The per-parameter Adam update with tiny-cuda-nn semantics (notes tiny-cuda-nn §C.2, official notes §5),
// defined once for the CPU trainer (engine/neural/adam.cpp) and the CUDA trainer (k_adam,
// trainer/cuda/update_kernels.cu). C++ and CUDA only (pointers; GLSL never trains), written in the
// shaders/shared/compat.h style: NB_FN is `__host__ __device__ inline` under nvcc.
//
//   g    : the gradient of the parameter, ALREADY divided by the loss scale (and the batch size where
//          the caller has not done so): the caller owns that scaling, the CPU and CUDA sums differ.
//   skip : grid (non-matrix) parameters with g == 0 exactly are skipped entirely (no moment decay, no
//          step increment): a sparse/lazy update of hash entries no sample touched. MLP (matrix)
//          parameters are always updated (skip_zero = 0).
//   g += l2 * w;  m = b1 m + (1-b1) g;  v = b2 v + (1-b2) g^2;  t = ++t
//   w -= lr * sqrt(1 - b2^t) / (1 - b1^t) / (sqrt(v) + eps) * m
// eps is added to sqrt of the UNCORRECTED v (tcnn's folded form; PyTorch differs by sqrt(1-b2^t) on
// eps). t is a per-parameter uint32 step counter, so a hash entry first touched late starts its own
// bias correction at t = 1. The fp16 copy of w (the shaders' weights) is the caller's: it rounds w
// after the update (CUDA: __float2half_rn in the same kernel; CPU: the model export); updates below half
// an fp16 ulp accumulate in the fp32 master, and a master of magnitude >= 65520 has an infinite copy.
// Range (float arithmetic, as tcnn): for |g| above sqrt(FLT_MAX / (1 - b2)) (5.8e20 at b2 = 0.999)
// (1 - b2) g^2 overflows, v becomes inf and the parameter stops moving for good (w, m stay finite); the
// trainers' gradients are many orders below that, and their guards skip a step with a non-finite gradient
// before it gets here. For |g| below ~1e-21 (1 - b2) g^2 underflows to 0 and the step, lr_t m / eps, is
// far below w's resolution.
#ifndef NB_ADAM_UPDATE_H
#define NB_ADAM_UPDATE_H

#include "shaders/shared/compat.h"

// Hyperparameters of one Adam call over one parameter group (MLP or grid).
struct GpuAdamRule {
    float lr;       // learning rate of this optimiser step (ExponentialDecay applied by the caller)
    float beta1, beta2, epsilon;
    float l2;       // MLP: l2_reg (1e-8); grid: non_matrix_l2_reg (0)
    uint skip_zero; // 1: a parameter whose g is exactly 0 is left untouched (grid); 0: always updated
};

// Bias-correction factors of per-parameter step t >= 1: sqrt(1 - b2^t) and 1 - b1^t. The CPU caches
// them per t (the same expressions, so the same values).
NB_FN float nb_adam_bias_sqrt(float beta2, uint t) { return sqrtf(1.0f - powf(beta2, float(t))); }
NB_FN float nb_adam_bias_div(float beta1, uint t) { return 1.0f - powf(beta1, float(t)); }

// One parameter. bias_sqrt/bias_div: optional tables of the two factors indexed by t (entries [0, n));
// a t outside (or null tables, n = 0) computes them. Returns false when the parameter was skipped
// (nothing changed), true when w, m, v and t were updated.
NB_FN bool nb_adam_update(NB_INOUT(float) w, NB_INOUT(float) m, NB_INOUT(float) v, NB_INOUT(uint) t, float g,
                          NB_IN(GpuAdamRule) r, const float* bias_sqrt, const float* bias_div, uint n) {
    if (r.skip_zero != 0u && g == 0.0f) return false;
    g += r.l2 * w;
    m = r.beta1 * m + (1.0f - r.beta1) * g;
    v = r.beta2 * v + (1.0f - r.beta2) * g * g;
    t += 1u;
    const float bs = t < n ? bias_sqrt[t] : nb_adam_bias_sqrt(r.beta2, t);
    const float bd = t < n ? bias_div[t] : nb_adam_bias_div(r.beta1, t);
    const float lr_t = r.lr * bs / bd;
    w -= lr_t / (sqrtf(v) + r.epsilon) * m;
    return true;
}

#endif // NB_ADAM_UPDATE_H
