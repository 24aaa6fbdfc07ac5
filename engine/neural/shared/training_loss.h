// The N-BVH training loss (paper §4.3 "Combined loss", official notes §4), defined once for the CPU
// trainer (engine/neural/losses.cpp composite_loss) and the CUDA trainer (the output layer of k_mlp,
// trainer/cuda/network_kernels.cu). C++ and CUDA only (pointers to the 8 outputs), written in the
// shaders/shared/compat.h style: NB_FN is `__host__ __device__ inline` under nvcc.
//
// Per sample, on the 8 network outputs AFTER the sigmoid (y in [0,1]); gradients are dL/dy
// (post-sigmoid), what reference_network backward() and the CUDA backward take:
//   L = w_vis * BCE(y0, t0) + w_depth * |y1 - t1| + w_normal * sum_i |N(y_i) - t_i| (i = 2..4)
//       + w_albedo * sum_i (y_i - t_i)^2 / (y_i^2 + 0.01) (i = 5..7)
//   BCE: p = clamp(y0, 1e-5, 1 - 1e-5), -(t log p + (1-t) log(1-p)) - H(t), dL/dy0 = -(t - p)/(p (1 - p))
//   (H(t) the target's entropy, 0 for t = 0 or 1: the value is the KL divergence, 0 at y = t, so a
//   soft target -- the stop probability of an alpha-blended surface, trainer/ground_truth.h -- leaves
//   no floor that the split ranking would chase; the gradient is the BCE's. Binary targets: the BCE)
//   (the official code divides by p - p^2, which cancels near p = 1: 1e-5 relative at the clamp and
//   3e-5 between host and device, measured on the H100; 1 - p is exact for p >= 1/2, so p (1 - p) is
//   within a few ulps everywhere -- same function, rounding only)
//        (evaluated at the clamped p, as tcnn: the gradient does not vanish in the clamped range, and
//        stays finite at y = 0 and y = 1: |dL/dy0| <= ~1e5).
//   L1: d/dy = sign(y - t) (0 when equal).
//   Normals, "linearised" (default, official): N(y) = 10 y - 4.5, dL/dy = 10 sign(N(y) - t); targets are
//        (n + 1)/2 of the unit shading normal. With normal_linear = 0, N(y) = y.
//   Relative L2 (albedo): the denominator y^2 + 0.01 is treated as a CONSTANT in the gradient,
//        dL/dy = 2 (y - t)/(y^2 + 0.01), exactly like tcnn's RelativeL2 (not the true derivative).
//   Masking: when t0 = 0 (no hit), depth/normal/albedo terms have value and gradient 0.
// Normalisation over the batch is the caller's (tcnn divides value and gradient by batch * 8 and scales
// gradients by the fp16 loss scale that Adam divides back out); so is the non-finite check of y.
#ifndef NB_TRAINING_LOSS_H
#define NB_TRAINING_LOSS_H

#include "shaders/shared/compat.h"
#include "shaders/shared/neural_config.h"

#define NB_BCE_CLAMP 1e-5f
#define NB_REL_L2_EPS 1e-2f
#define NB_NORMAL_LINEAR_SCALE 10.0f
#define NB_NORMAL_LINEAR_OFFSET 4.5f

// Weights (paper 2, 2, 1, 1; the official code uses 1, 1, 1, 1) and switches of the composite loss.
struct GpuLossConfig {
    float w_visibility, w_depth, w_normal, w_albedo;
    uint normal_linear;      // 1: N(y) = 10 y - 4.5
    uint visibility_masking; // 1: no depth/normal/albedo terms where the target has no hit (t0 = 0)
};

NB_FN float nb_loss_sign(float x) { return x > 0.0f ? 1.0f : (x < 0.0f ? -1.0f : 0.0f); }

// Entropy of a visibility target in nats (0 for t = 0 or 1).
NB_FN float nb_target_entropy(float t) {
    return (t > 0.0f && t < 1.0f) ? -(t * logf(t) + (1.0f - t) * logf(1.0f - t)) : 0.0f;
}

// Each term unweighted: returns its value, writes dvalue/dy.
NB_FN float nb_loss_bce(float y, float t, NB_OUT(float) d) {
    const float p = fminf(fmaxf(y, NB_BCE_CLAMP), 1.0f - NB_BCE_CLAMP);
    d = -(t - p) / (p * (1.0f - p));
    // Minus the target's entropy (0 for t = 0 or 1, where the BCE itself is >= 0: the same value).
    return fmaxf(-(t * logf(p) + (1.0f - t) * logf(1.0f - p)) - nb_target_entropy(t), 0.0f);
}
NB_FN float nb_loss_l1(float y, float t, NB_OUT(float) d) {
    const float e = y - t;
    d = nb_loss_sign(e);
    return fabsf(e);
}
NB_FN float nb_loss_normal(float y, float t, uint linear, NB_OUT(float) d) {
    const float s = linear != 0u ? NB_NORMAL_LINEAR_SCALE : 1.0f;
    const float o = linear != 0u ? NB_NORMAL_LINEAR_OFFSET : 0.0f;
    const float e = s * y - o - t;
    d = s * nb_loss_sign(e);
    return fabsf(e);
}
NB_FN float nb_loss_rel_l2(float y, float t, NB_OUT(float) d) {
    const float e = y - t;
    const float den = y * y + NB_REL_L2_EPS;
    d = 2.0f * e / den;
    return e * e / den;
}

// The weight of output slot i (0..7).
NB_FN float nb_loss_weight(NB_IN(GpuLossConfig) c, uint i) {
    return i == NB_OUT_VISIBILITY ? c.w_visibility
           : i == NB_OUT_DEPTH    ? c.w_depth
           : i < NB_OUT_ALBEDO    ? c.w_normal
                                  : c.w_albedo;
}

// One sample: y, t = NB_MLP_OUTPUTS outputs and targets. Writes value[i], the UNWEIGHTED loss of slot i,
// and dl_dy[i], the gradient of the WEIGHTED loss (w_i * d value_i / dy_i); returns the weighted total
// sum_i w_i value_i, summed in slot order.
NB_FN float nb_composite_loss(const float* y, const float* t, NB_IN(GpuLossConfig) c, float* value, float* dl_dy) {
    for (uint i = 0u; i < NB_MLP_OUTPUTS; ++i) {
        value[i] = 0.0f;
        dl_dy[i] = 0.0f;
    }
    float d = 0.0f;
    value[NB_OUT_VISIBILITY] = nb_loss_bce(y[NB_OUT_VISIBILITY], t[NB_OUT_VISIBILITY], d);
    dl_dy[NB_OUT_VISIBILITY] = c.w_visibility * d;
    if (!(c.visibility_masking != 0u && t[NB_OUT_VISIBILITY] <= 0.0f)) {
        value[NB_OUT_DEPTH] = nb_loss_l1(y[NB_OUT_DEPTH], t[NB_OUT_DEPTH], d);
        dl_dy[NB_OUT_DEPTH] = c.w_depth * d;
        for (uint i = NB_OUT_NORMAL; i < NB_OUT_NORMAL + 3u; ++i) {
            value[i] = nb_loss_normal(y[i], t[i], c.normal_linear, d);
            dl_dy[i] = c.w_normal * d;
        }
        for (uint i = NB_OUT_ALBEDO; i < NB_OUT_ALBEDO + 3u; ++i) {
            value[i] = nb_loss_rel_l2(y[i], t[i], d);
            dl_dy[i] = c.w_albedo * d;
        }
    }
    float total = 0.0f;
    for (uint i = 0u; i < NB_MLP_OUTPUTS; ++i) total += nb_loss_weight(c, i) * value[i];
    return total;
}

// dL/dz of the pre-sigmoid output z from dL/dy: dL/dy * y (1 - y) (0 where the sigmoid saturated).
NB_FN float nb_presigmoid_gradient(float dl_dy, float y) { return dl_dy * y * (1.0f - y); }

#endif // NB_TRAINING_LOSS_H
