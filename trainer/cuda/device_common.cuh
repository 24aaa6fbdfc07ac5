// Shared by the .cu files of the CUDA trainer: error checks, device PCG32 (bit-identical to
// trainer/training_rays.h Pcg32) and the device-side views of the uploaded asset and batch.
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

#define NBVH_CUDA_CHECK(expr)                                                                          \
    do {                                                                                               \
        cudaError_t err_ = (expr);                                                                     \
        if (err_ != cudaSuccess)                                                                       \
            throw std::runtime_error(std::string("CUDA error: ") + cudaGetErrorString(err_) + " at " +  \
                                     __FILE__ + ":" + std::to_string(__LINE__) + " (" #expr ")");      \
    } while (0)

namespace nbvh::cuda {

// Same generator and stream split as the CPU (training_rays.h), so both backends can draw the same rays.
struct DevPcg32 {
    uint64_t state, inc;
    __device__ DevPcg32(uint64_t seed, uint64_t stream) : state(0), inc((stream << 1u) | 1u) {
        next_u32();
        state += seed;
        next_u32();
    }
    __device__ uint32_t next_u32() {
        const uint64_t old = state;
        state = old * 6364136223846793005ull + inc;
        const uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
        const uint32_t rot = uint32_t(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
    }
    __device__ float next_float() { return float(next_u32() >> 8) * (1.0f / 16777216.0f); }
};

struct DevAsset {
    const float* node_boxes = nullptr;   // 6 per base node
    const uint2* children = nullptr;     // per base node
    uint32_t base_nodes = 0;
    const GpuBvhNode* mesh_nodes = nullptr;
    const float* tri_v = nullptr;        // 9 per triangle
    const float* tri_n = nullptr;        // 9 per triangle
    const float* tri_a = nullptr;        // 9 per triangle: base colour factor per vertex
    const float* tri_uv = nullptr;       // 6 per triangle
    const int32_t* tri_tex = nullptr;    // per triangle, -1 = untextured
    const uint32_t* texels = nullptr;
    const uint32_t* tex_info = nullptr;  // 3 per texture: first texel, width, height
    const float* srgb = nullptr;         // 256 entries
    const float* tri_g = nullptr;        // 3 per triangle
    GpuEncodingBox enc;
    const float* part_boxes = nullptr;    // 6 per part: sampling box lo xyz, extent xyz
    const uint32_t* part_roots = nullptr; // base-BVH root per part
    uint32_t parts = 1;
    float min_exit = 0.0f;
};

#define NB_CUDA_MAX_CUTS 8
struct DevCuts {
    const int32_t* leaf_of[NB_CUDA_MAX_CUTS];
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
    float* grid_grad = nullptr;              // fast mode: float atomics
    unsigned long long* grid_grad_fx = nullptr; // deterministic mode: fixed point (two's complement)
    uint32_t grid_values = 0;
};

// Fixed-point scale of the deterministic grid-gradient accumulation (values are loss-scaled).
#define NB_CUDA_FIXED_SCALE 16777216.0f

// Flag bits of the non-finite guard.
#define NB_GUARD_OUTPUT 1u
#define NB_GUARD_GRADIENT 2u

// Launchers (sampling_kernels.cu, network_kernels.cu).
void launch_sample(const DevAsset& a, const DevCuts& c, const DevBatch& b, uint32_t batch, uint64_t seed,
                   uint32_t step, unsigned long long* draws, uint32_t* valid, cudaStream_t s);
void launch_ground_truth(const DevAsset& a, const DevBatch& b, cudaStream_t s);
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
