// The CUDA training backend (issue 5): every part of a step on the GPU (sampling and first-leaf search
// over the cut, ground truth on the triangle BVH, encoding, fused tensor-core MLP, losses, grid
// backward, guarded Adam, per-leaf statistics). See trainer/cuda/README.md for the design and its
// precision and determinism contracts.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "trainer/trainer_backend.h"
#include "trainer/training_asset.h"

namespace nbvh {

struct CudaBackendOptions {
    // Deterministic mode: grid gradients accumulate in 64-bit fixed point (order-independent integer
    // atomics) instead of fp32 atomics; everything else is already order-fixed. Bit-reproducible
    // runs for a seed on one GPU model (nbvh train --deterministic, TrainOptions::deterministic).
    bool deterministic = false;
    float loss_scale = 128.0f; // per-sample loss scale of the fp16 backward (halved on overflow)
    // Draw step k+1's rays and ground truth while step k's network part runs (a second stream). Step
    // k+1 then samples with step k's keep probabilities (one step older than without prefetch); a cut
    // change drops the batch drawn ahead. Same rays otherwise (tests/cuda/cuda_prefetch_test.cpp).
    bool prefetch = true;
};

// One drawn sample as the CUDA step saw it (tests).
struct CudaDebugSample {
    glm::vec3 origin{0.0f}, dir{0.0f};
    float length = 0.0f;
    int32_t leaf = -1;
    uint32_t cut = 0;
    std::array<float, NB_MLP_OUTPUTS> target{};
};

struct CudaPhaseTimes { // milliseconds of the last step (set_timing(true))
    float sample = 0, truth = 0, encode = 0, mlp = 0, grid_backward = 0, reduce_adam = 0;
};

class CudaTrainerBackend : public TrainerBackend {
public:
    // Samples and batch-mean gradients (MLP, grid; loss scale removed) of the last step.
    virtual void read_last_step(std::vector<CudaDebugSample>& samples, std::vector<float>& mlp_grad,
                                std::vector<float>& grid_grad) const = 0;
    // The fp16 copies of the weights the kernels read (bits; MLP, grid), refreshed by every Adam step.
    virtual void read_half_weights(std::vector<uint16_t>& mlp, std::vector<uint16_t>& grid) const = 0;
    virtual void set_timing(bool on) = 0;
    virtual CudaPhaseTimes phase_times() const = 0;
    virtual float loss_scale() const = 0;
};

// Name of the CUDA device used (this thread's current one; empty when none).
std::string cuda_device_name();
// Trains on the GPU a Vulkan context chose (`nbvh study --device gpu:N`): makes the CUDA device with this
// UUID (vk::DeviceFeatures::device_uuid) current on the calling thread. Throws nbvh::Error naming the
// UUID when no CUDA device has it.
void cuda_use_device_uuid(const std::string& uuid);

std::unique_ptr<CudaTrainerBackend> make_cuda_backend_ex(const TrainingAsset& asset, const NeuralConfig& config,
                                                         const neural::AdamConfig& adam,
                                                         const CudaBackendOptions& options, uint64_t seed);

} // namespace nbvh
