// The portable CPU training backend: the numerical reference of the trainer. Multi-threaded over the
// batch with std::thread; each thread samples its share of rays, traces the ground truth, runs the
// network forward and backward in tiles of 64 samples (engine/neural/batched_network.h: the CPU
// reference's math as small matrix-matrix products) and accumulates per-thread gradients; the host thread reduces them, checks them for non-finite values and runs Adam
// (engine/neural/adam.h) on the fp32 master weights.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/neural/reference_network.h"
#include "trainer/trainer_backend.h"
#include "trainer/training_asset.h"

namespace nbvh {

// One drawn training sample: the forward segment of a ray through its first cut leaf, moved so that
// the segment starts at the origin (t in [0, length]); `cut`/`leaf` say which cut and slot it trains.
struct TrainingSample {
    glm::vec3 origin{0.0f};
    glm::vec3 dir{0.0f};
    float length = 0.0f;
    uint32_t cut = 0;
    int32_t leaf = -1;
};

// Draws one sample as the paper does (§3, §3.3): origin uniform in the sampling box, direction
// uniform, dilation 1e-5 + U 1e-4, first leaf of a cut picked uniformly; misses are redrawn, and for
// cuts[0] the survival roulette rejects (and redraws) with 1 - keep_probability. `leaf_draws`
// (size of cuts[0], may be null) counts every ray that met a leaf of cuts[0] first. Gives up after
// `max_draws` rays (returns leaf = -1), so a cut that rays cannot reach never hangs training.
// Attempt k draws its random numbers from where.attempt_rng(k) (trainer/pcg32.h).
TrainingSample draw_training_sample(const TrainingAsset& asset, std::span<const TrainingCut* const> cuts,
                                    const SampleSlot& where, uint32_t* leaf_draws, uint64_t& draws,
                                    uint32_t max_draws = kMaxSampleAttempts);

} // namespace nbvh
