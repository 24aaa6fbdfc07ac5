// The host side of N-BVH training (paper §3.2 and §3.3, official notes §6-7): owns the N-BVH cut
// (engine/neural/nbvh_tree.h), the per-node error statistics, the exponential split schedule
// (trainer/split_scheduler.h), the levels of detail and the learning-rate schedule, and drives one
// TrainerBackend (cpu/ or cuda/) step by step.
//
// Differences from the official code, on purpose (notes §14): rejected samples are redrawn (no stale
// replays, no step on zero buffers); the learning rate decays during the final stage (exponentially to
// final_lr_factor x lr); splitting stops at a target node count; every step is guarded against
// non-finite losses and gradients (skipped, counted, reported); leaves without samples yet are kept
// with probability 1 so that fresh children get an error estimate quickly.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "engine/neural/nbvh_tree.h"
#include "engine/neural/neural_config.h"
#include "engine/neural/reference_network.h"
#include "trainer/split_scheduler.h"
#include "trainer/trainer_backend.h"
#include "trainer/training_asset.h"

namespace nbvh {

enum class BackendChoice { cpu, cuda, automatic };

struct TrainOptions {
    NeuralConfig network;              // network.log2_hash_size is --hash-log2
    uint32_t target_nodes = 1000;      // N-BVH node count at which splitting stops (--nodes)
    uint32_t steps = 1000;             // total optimiser steps (split stage + final stage)
    float split_fraction = 0.6f;       // share of the steps during which the cut grows
    uint32_t batch_size = 1u << 11;    // trained samples per step
    uint32_t lods = 1;                 // cuts kept as levels of detail (paper §3.4)
    uint64_t seed = 1337;
    float learning_rate = 1e-2f;       // Adam (paper §4)
    float final_lr_factor = 0.1f;      // lr at the end of the final stage, relative
    uint32_t threads = 0;              // CPU backend threads (0 = all cores)
    bool deterministic = false;        // CUDA backend: bit-reproducible steps (--deterministic; the CPU always is)
    uint32_t max_consecutive_skips = 50; // then training fails with nbvh::Error
};

// Defaults per backend: the paper's (2^18 rays, 10k steps, hash 2^18, ~2.4k nodes) for CUDA; a
// scaled-down schedule for the CPU so the demo trains in a few minutes on 2 cores.
TrainOptions default_train_options(BackendChoice backend);
// Throws nbvh::Error naming a bad option (zero steps/batch, too many LoDs, hash size out of range...).
void validate(const TrainOptions& options);

// The split schedule used for `options`: splits every `interval` steps over the split stage, with a
// growth factor chosen so the simulated node count reaches target_nodes.
SplitSchedule make_split_schedule(const TrainOptions& options);

// Adam (paper §4: lr 1e-2, default betas) with the learning-rate schedule of `options`: constant
// during the split stage, then ExponentialDecay in 5 equal intervals down to final_lr_factor x lr.
neural::AdamConfig make_adam_config(const TrainOptions& options);

struct TrainProgress {
    uint32_t step = 0, steps = 0;
    uint32_t nodes = 0, leaves = 0;
    double loss = 0.0;           // weighted total of the last step
    double samples_per_s = 0.0;  // trained samples per second, running average
    double eta_s = 0.0;
    bool final_stage = false;
};

struct StepLog {
    uint32_t step = 0;
    uint32_t nodes = 0, leaves = 0;
    float learning_rate = 0.0f;
    LossTerms loss;
    bool skipped = false;
    double seconds = 0.0;        // wall time of the step
};

struct TrainResult {
    NbvhTree tree;                        // final cut, LoDs registered (frozen)
    neural::NetworkWeights weights;       // fp32 master weights
    std::vector<StepLog> log;
    uint32_t skipped_steps = 0;
    double seconds = 0.0;
    double samples_per_s = 0.0;
    std::string backend;
};

// Resolves `automatic` (CUDA when this build has it and a GPU is usable, else CPU).
BackendChoice resolve_backend(BackendChoice choice);
// The CUDA device that this host thread's CUDA training runs on: the one whose UUID is `uuid`, in the
// form of DeviceFeatures::device_uuid (the Vulkan GPU a user picked with --device gpu:N, so training and
// rendering share one GPU on a host with several). CUDA's current device is per thread: call it in the
// thread that trains, before make_backend. Empty: leave the choice to CUDA (its first device, or
// CUDA_VISIBLE_DEVICES). Throws nbvh::Error when no CUDA device has that UUID or the build has no CUDA.
void use_cuda_device(const std::string& uuid);
// The backend for `options` (network init from options.seed, Adam from make_adam_config). Throws
// nbvh::Error when CUDA is asked for and not available.
std::unique_ptr<TrainerBackend> make_backend(BackendChoice choice, const TrainingAsset& asset,
                                             const TrainOptions& options);

using ProgressCallback = std::function<void(const TrainProgress&)>;

// Trains one asset. `make_backend` lets tests and the CLI choose the backend; by default the CPU one.
TrainResult train_asset(const TrainingAsset& asset, const TrainOptions& options, TrainerBackend& backend,
                        const ProgressCallback& progress = {});

// The cut of `lod` of a tree as a TrainingCut over the asset's base BVH (for evaluation).
TrainingCut cut_of_tree(const TrainingAsset& asset, const NbvhTree& tree, uint32_t lod);

// Writes the per-step log as CSV: step,nodes,leaves,lr,loss,visibility,depth,normal,albedo,skipped,seconds.
void write_train_log_csv(const std::vector<StepLog>& log, const std::string& path);

} // namespace nbvh
