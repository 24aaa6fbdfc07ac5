// Shared by the .cu files of the CUDA trainer: error checks (PCG32: trainer/pcg32.h, one definition
// with the CPU) and the device-side views of the uploaded asset and batch.
#pragma once
#include <cuda_fp16.h>
#include <cuda_runtime.h>

#include <cstdint>
#include <stdexcept>
#include <string>

#include "shaders/shared/bvh_node.h"
#include "shaders/shared/hashgrid.h"
#include "shaders/shared/intersect.h"
#include "shaders/shared/mlp.h"
#include "shaders/shared/neural_query.h"
#include "engine/neural/shared/training_loss.h"
#include "trainer/cuda/cuda_core.h"
#include "trainer/cuda/cut_tree.h"
#include "trainer/pcg32.h"

#define NBVH_CUDA_CHECK(expr)                                                                          \
    do {                                                                                               \
        cudaError_t err_ = (expr);                                                                     \
        if (err_ != cudaSuccess)                                                                       \
            throw std::runtime_error(std::string("CUDA error: ") + cudaGetErrorString(err_) + " at " +  \
                                     __FILE__ + ":" + std::to_string(__LINE__) + " (" #expr ")");      \
    } while (0)

namespace nbvh::cuda {

struct DevAsset {
    const GpuWideNode* mesh_wide = nullptr; // the ground truth's triangle BLAS (4-wide)
    const float* tri_v = nullptr;        // 9 per triangle
    const float* tri_n = nullptr;        // 9 per triangle
    const float* tri_a = nullptr;        // 9 per triangle: base colour factor per vertex
    const float* tri_uv = nullptr;       // 6 per triangle
    const int32_t* tri_tex = nullptr;    // per triangle, -1 = untextured
    const uint32_t* texels = nullptr;
    const uint32_t* tex_info = nullptr;  // 3 per texture: first texel, width, height
    const float* srgb = nullptr;         // 256 entries
    const float* tri_g = nullptr;        // 3 per triangle
    const TriCoverage* coverage = nullptr; // per triangle; null: every triangle opaque
    const TriNormalMap* normal_maps = nullptr; // per triangle; null: no normal maps
    GpuEncodingBox enc;
    const float* part_boxes = nullptr;    // 6 per part: sampling box lo xyz, extent xyz
    uint32_t parts = 1;
    float min_exit = 0.0f;
};

// Levels of detail a step may sample (a limit of the options, not an array size).
#define NB_CUDA_MAX_CUTS 8
struct DevCuts {
    const CutNode* nodes = nullptr;      // every cut's compact tree (cut_tree.h)
    const uint32_t* roots = nullptr;     // [cut * parts + part]: the part's root in `nodes` (kCutNone: empty)
    uint32_t count = 0;
    const float* keep = nullptr;         // cuts[0] keep probability per leaf
    uint32_t* leaf_draws = nullptr;      // cuts[0] draws per leaf (atomics)
};

// Structure-of-arrays batch on the device.
struct DevBatch {
    float* origin = nullptr;   // 3N
    float* dir = nullptr;      // 3N
    float* length = nullptr;   // N
    int32_t* leaf = nullptr;   // N (-1: starved, not trained)
    uint32_t* cut = nullptr;   // N
    float* target = nullptr;   // 8N
    float* points = nullptr;   // 9N encoded points
    __half* features = nullptr; // 96N
    float* dfeatures = nullptr; // 96N, dL/dfeature x loss scale
    float* loss = nullptr;     // 5N: vis, depth, normal, albedo (unweighted, channel means), total
    uint32_t n = 0;
};

struct DevNetwork {
    GpuHashLevel levels[NB_GRID_MAX_LEVELS];
    const __half* grid_h = nullptr;
    const __half* mlp_h = nullptr;
    float* grid_grad = nullptr;    // fast mode: the coarse levels' values (fp32, flushed from shared memory)
    __half* grid_grad_h = nullptr; // fast mode: the fine levels' values (fp16 vector reductions)
    unsigned long long* grid_grad_fx = nullptr; // deterministic mode: fixed point (two's complement)
    uint32_t grid_values = 0;
};

// Coarse levels of the fast mode's grid backward: the leading levels whose values fit the shared-memory
// accumulator (k_grid_backward_coarse); none in the deterministic mode. `values`: their value count, where
// the fine levels' fp16 gradient starts.
struct CoarseSplit {
    uint32_t levels = 0, values = 0;
};
CoarseSplit coarse_split(const DevNetwork& net, bool deterministic);

// Fixed-point scale of the deterministic grid-gradient accumulation (values are loss-scaled).
#define NB_CUDA_FIXED_SCALE 16777216.0f

// Flag bits of the non-finite guard.
#define NB_GUARD_OUTPUT 1u
#define NB_GUARD_GRADIENT 2u

// Launchers (sampling_kernels.cu, network_kernels.cu).
void launch_sample(const DevAsset& a, const DevCuts& c, const DevBatch& b, uint32_t batch, uint64_t seed,
                   uint32_t step, unsigned long long* draws, uint32_t* valid, cudaStream_t s);
// `seed`, `step`: the batch's (SampleSlot), for the stochastic coverage of blended surfaces.
void launch_ground_truth(const DevAsset& a, const DevBatch& b, uint64_t seed, uint32_t step, cudaStream_t s);
void launch_encode(const DevNetwork& net, const DevBatch& b, cudaStream_t s);
struct LossParams {
    GpuLossConfig loss; // the composite loss (engine/neural/shared/training_loss.h)
    float loss_scale;   // per-sample fp16 loss scale applied to dL/dz
};
int mlp_blocks_for(uint32_t n);
void mlp_prepare();
void launch_mlp(const DevNetwork& net, const DevBatch& b, const LossParams& lp, float* slices, int blocks,
                uint32_t* flag, cudaStream_t s);
void launch_grid_backward(const DevNetwork& net, const DevBatch& b, bool deterministic, uint32_t* flag,
                          cudaStream_t s);

} // namespace nbvh::cuda
