// The N-BVH training loss on the CPU: the formulas, constants and the definition of every term live in
// engine/neural/shared/training_loss.h (shared with the CUDA trainer); this is the std::array front end
// the CPU trainer and the tests call. Weights: paper 2, 2, 1, 1 (default); the official code uses 1, 1,
// 1, 1. Batch normalisation and the fp16 loss scale are the caller's.
#pragma once
#include <array>

#include "engine/neural/reference_network.h"
#include "engine/neural/shared/training_loss.h"

namespace nbvh::neural {

struct LossConfig {
    float w_visibility = 2.0f;
    float w_depth = 2.0f;
    float w_normal = 1.0f;
    float w_albedo = 1.0f;
    bool normal_linear = true;
    bool visibility_masking = true;
};

// The shared header's form of the config.
GpuLossConfig to_gpu(const LossConfig& cfg);

// Targets in output slots: visibility (0 miss, 1 hit; an alpha-blended surface's stop probability,
// trainer/ground_truth.h), depth u in [0,1] (nb_encode_depth_target), normal (n+1)/2, albedo. A miss
// has visibility 0 (the other slots are ignored when masking).
using Targets = std::array<float, NB_MLP_OUTPUTS>;

// Per-sample weighted loss; writes dL/dy (post-sigmoid) when dl_dy != nullptr and the weighted per-slot
// losses when per_slot != nullptr (they sum to the return value). Non-finite y or targets are a
// caller bug (NBVH_CHECK).
float composite_loss(const Outputs& y, const Targets& t, const LossConfig& cfg, Outputs* dl_dy = nullptr,
                     std::array<float, NB_MLP_OUTPUTS>* per_slot = nullptr);

// dL/dz of the pre-sigmoid output z from dL/dy: dL/dy * y (1 - y).
inline float presigmoid_gradient(float dl_dy, float y) { return nb_presigmoid_gradient(dl_dy, y); }

// Target of one ground-truth hit (see neural_query.h nb_encode_depth_target for u).
Targets make_targets(bool hit, float depth_u, vec3 unit_normal, vec3 albedo, float visibility = 1.0f);

} // namespace nbvh::neural
