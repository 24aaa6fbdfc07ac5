// Accuracy of a trained network against the triangle ground truth on fresh random rays (same
// distribution as training, paper §3: origins in the 1.5x box, uniform directions), each queried
// through its first leaf of a cut with the CPU reference network. Used by the training tests, the
// benchmark and `nbvh train` (printed after training).
#pragma once
#include <cstdint>
#include <vector>

#include "engine/neural/reference_network.h"
#include "trainer/training_asset.h"
#include "trainer/training_rays.h"

namespace nbvh {

struct EvalStats {
    uint32_t rays = 0;                 // rays that met a leaf of the cut (evaluated)
    double visibility_agreement = 0.0; // fraction with (y0 > 0.5) == (ground-truth visibility > 0.5)
    uint32_t both_hit = 0;             // rays where both say hit (depth/normal measured on these)
    double depth_mae = 0.0;            // mean |t_pred - t_gt| / segment length (local depth units)
    double depth_p90 = 0.0;            // 90th percentile of the same
    double depth_mae_rel_asset = 0.0;  // mean |t_pred - t_gt| / asset box diagonal
    double normal_mean_deg = 0.0;      // mean angle between predicted and true shading normal
    double albedo_mae = 0.0;           // mean absolute albedo error per channel
};

// `leaves`: base-BVH node ids of the cut (e.g. the final cut's leaves mapped to base nodes).
// `part`: evaluate one part of a multi-asset run (rays of its sampling box); -1: every part, as trained.
EvalStats evaluate_network(const TrainingAsset& asset, const TrainingCut& cut, const neural::NetworkWeights& weights,
                           uint32_t rays, uint64_t seed, int32_t part = -1);

} // namespace nbvh
