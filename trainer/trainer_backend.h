// The interface every training backend implements (cpu/ is the portable numerical reference, cuda/
// the fast one). A backend owns the network parameters, the optimiser state, ray sampling and the
// ground truth for one step; the host driver (trainer/trainer.h) owns the N-BVH cut, the split
// schedule and the learning-rate schedule, and decides splits from the per-leaf statistics a step
// returns (paper §3.2 "Node error"; official notes §7 for what q and p are).
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "engine/neural/adam.h"
#include "engine/neural/neural_config.h"
#include "engine/neural/reference_network.h"
#include "trainer/training_rays.h"

namespace nbvh {

struct TrainingAsset; // trainer/training_asset.h

// Mean loss per trained sample, per term, unweighted (the total applies the paper's 2/2/1/1 weights).
// Depth, normal and albedo are averaged over the samples whose ground truth is a hit (masked terms).
struct LossTerms {
    double visibility = 0.0; // BCE
    double depth = 0.0;      // L1 of the local depth
    double normal = 0.0;     // L1 of the normal (mean over 3 channels)
    double albedo = 0.0;     // relative L2 (mean over 3 channels)
    double total = 0.0;      // 2 vis + 2 depth + normal + albedo, masked terms weighted by the hit ratio
};

// Per leaf of the current cut, accumulated over one step. The host sums these from the node's
// creation: q = loss_sum / samples (mean loss of a trained sample), p = draws / rays drawn for the
// current cut (StepStats::draws / cuts): the probability that a training ray meets the leaf first,
// measured before the survival roulette.
struct LeafStepStats {
    double loss_sum = 0.0;  // weighted total loss of the samples trained in this leaf
    uint32_t samples = 0;   // samples that survived the roulette and were trained
    uint32_t draws = 0;     // rays whose first leaf was this one (kept or rejected)
};

struct StepParams {
    uint32_t step = 0;
    uint32_t batch_size = 0;          // trained samples per step (rejected draws are redrawn)
    float learning_rate = 1e-2f;      // informational: the backend's Adam applies its AdamConfig decay
    uint64_t seed = 0;
    // cuts[0] is the cut being grown (statistics are reported for its leaves, keep probabilities
    // are read from it); cuts[1..] are frozen coarser LoD cuts also trained (paper §3.4: each sample
    // picks one cut uniformly).
    std::vector<const TrainingCut*> cuts;
    uint64_t cut_version = 0; // bumped by the host whenever any cut changes (GPU backends re-upload)
};

struct StepStats {
    LossTerms loss;
    std::vector<LeafStepStats> leaves; // size of cuts[0]
    uint32_t samples = 0;              // trained samples (== batch_size unless sampling starved)
    uint64_t draws = 0;                // rays drawn (including misses and rejections)
    uint32_t hits = 0;                 // trained samples whose ground truth is a hit
    bool skipped = false;              // non-finite loss or gradient: parameters left untouched
    std::string skip_reason;
};

class TrainerBackend {
public:
    virtual ~TrainerBackend() = default;
    virtual const char* name() const = 0;
    // One optimiser step: sample, ground truth, forward, loss, backward, guard, Adam.
    virtual StepStats step(const StepParams& params) = 0;
    // Current fp32 master weights (MLP then grid, layout of engine/neural/reference_network.h).
    virtual void read_weights(neural::NetworkWeights& out) const = 0;
};

struct CpuBackendOptions {
    uint32_t threads = 0; // 0 = hardware concurrency
};

// trainer/cpu/cpu_backend.cpp. `asset` must outlive the backend.
// Network initialised from `seed` (tcnn init, reference_network.h); `adam` includes the learning-rate
// schedule (trainer.h make_adam_config).
std::unique_ptr<TrainerBackend> make_cpu_backend(const TrainingAsset& asset, const NeuralConfig& config,
                                                 const neural::AdamConfig& adam, const CpuBackendOptions& options,
                                                 uint64_t seed);

#if defined(NBVH_HAVE_CUDA)
// trainer/cuda/ (built when nvcc is found). cuda_backend_available() is false without a usable GPU.
bool cuda_backend_available();
// deterministic: order-independent gradient sums, bit-reproducible steps (trainer/cuda/README.md).
std::unique_ptr<TrainerBackend> make_cuda_backend(const TrainingAsset& asset, const NeuralConfig& config,
                                                  const neural::AdamConfig& adam, uint64_t seed,
                                                  bool deterministic = false);
#endif

} // namespace nbvh
