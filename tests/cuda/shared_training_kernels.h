// Device evaluation of the shared training math (engine/neural/shared/adam_update.h, training_loss.h) for
// shared_training_device_test.cpp: the kernels (shared_training_kernels.cu, nvcc) apply the very functions
// the CPU test evaluates on the host to arrays of cases, so the two compilers' results can be compared.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "engine/neural/shared/adam_update.h"
#include "engine/neural/shared/training_loss.h"

namespace nbvh::test {

// One nb_adam_update call: inputs w, m, v, t, g, rule; outputs w, m, v, t and updated (0/1).
struct AdamCase {
    float w, m, v;
    uint32_t t;
    float g;
    GpuAdamRule rule;
    uint32_t updated;
};

// One nb_composite_loss call (+ nb_presigmoid_gradient per output).
struct LossCase {
    float y[NB_MLP_OUTPUTS], t[NB_MLP_OUTPUTS];
    GpuLossConfig cfg;
    float value[NB_MLP_OUTPUTS], dl_dy[NB_MLP_OUTPUTS], dl_dz[NB_MLP_OUTPUTS], total;
};

// Host reference: the same functions compiled by the host compiler.
void apply_on_host(std::vector<AdamCase>& adam, std::vector<LossCase>& loss);
// The same on the first CUDA device; returns "" or the CUDA error.
std::string apply_on_device(std::vector<AdamCase>& adam, std::vector<LossCase>& loss);

} // namespace nbvh::test
