// The N-BVH training loss (paper §4.3 "Combined loss", official notes §4), per sample, on the 8
// network outputs AFTER the sigmoid (y in (0,1)); gradients are dL/dy (post-sigmoid), which is what
// reference_network backward() and the CUDA trainer's backward take.
//
//   L = w_vis * BCE(y0, t0) + w_depth * |y1 - t1| + w_normal * sum_i |N(y_i) - t_i| (i = 2..4)
//       + w_albedo * sum_i (y_i - t_i)^2 / (y_i^2 + 0.01) (i = 5..7)
//   BCE: p = clamp(y0, 1e-5, 1 - 1e-5), -(t log p + (1-t) log(1-p)), dL/dy0 = -(t - p)/(p - p^2)
//        (evaluated at the clamped p, as tcnn: the gradient does not vanish in the clamped range).
//   L1: d/dy = sign(y - t) (0 when equal).
//   Normals, "linearised" (default, official): N(y) = 10 y - 4.5, dL/dy = 10 sign(N(y) - t); targets are
//        (n + 1)/2 of the unit shading normal. With normal_linear = false, N(y) = y.
//   Relative L2 (albedo): the denominator y^2 + 0.01 is treated as a CONSTANT in the gradient,
//        dL/dy = 2 (y - t)/(y^2 + 0.01), exactly like tcnn's RelativeL2 (not the true derivative).
//   Masking: when t0 < 0.5 (no hit), depth/normal/albedo terms have value and gradient 0.
// Weights: paper 2, 2, 1, 1 (default). The official code uses 1, 1, 1, 1. Normalisation over the batch
// is the caller's: tcnn divides value and gradient by batch * 8 (output dims) and scales gradients by
// the fp16 loss scale (128) that Adam divides back out.
#pragma once
#include <array>

#include "engine/neural/reference_network.h"

namespace nbvh::neural {

struct LossConfig {
    float w_visibility = 2.0f;
    float w_depth = 2.0f;
    float w_normal = 1.0f;
    float w_albedo = 1.0f;
    bool normal_linear = true;
    bool visibility_masking = true;
};

#define NB_BCE_CLAMP 1e-5f
#define NB_REL_L2_EPS 1e-2f
#define NB_NORMAL_LINEAR_SCALE 10.0f
#define NB_NORMAL_LINEAR_OFFSET 4.5f

// Targets in output slots: visibility (0/1), depth u in [0,1] (nb_encode_depth_target), normal
// (n+1)/2, albedo. A miss has visibility 0 (the other slots are ignored when masking).
using Targets = std::array<float, NB_MLP_OUTPUTS>;

// Per-sample weighted loss; writes dL/dy (post-sigmoid) when dl_dy != nullptr and the weighted per-slot
// losses when per_slot != nullptr (they sum to the return value). Non-finite y or targets are a
// caller bug (NBVH_CHECK).
float composite_loss(const Outputs& y, const Targets& t, const LossConfig& cfg, Outputs* dl_dy = nullptr,
                     std::array<float, NB_MLP_OUTPUTS>* per_slot = nullptr);

// dL/dz of the pre-sigmoid output z from dL/dy: dL/dy * y (1 - y).
inline float presigmoid_gradient(float dl_dy, float y) { return dl_dy * y * (1.0f - y); }

// Target of one ground-truth hit (see neural_query.h nb_encode_depth_target for u).
Targets make_targets(bool hit, float depth_u, vec3 unit_normal, vec3 albedo);

} // namespace nbvh::neural
