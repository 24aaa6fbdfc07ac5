// Kernels of a training step after the grid backward (update_kernels.cu): per-leaf statistics, the MLP
// gradient's reduction, the non-finite guard's checks and Adam; and the fp16 copy of the initial weights.
// Launched by cuda_core.cu on its streams.
#pragma once
#include "engine/neural/shared/adam_update.h"
#include "trainer/cuda/device_common.cuh"

namespace nbvh::cuda {

// Copies of the per-leaf counters that k_stats's blocks spread their atomics over (block b adds to copy
// b % kLeafCopies), folded afterwards: a leaf hit by thousands of samples took as many atomics on one
// address. Counter buffers hold kLeafCopies x leaves values.
constexpr uint32_t kLeafCopies = 8;

// Adam's bias-correction factors for per-parameter steps t < kAdamBiasTable, computed once on the device
// by the same functions k_adam would call (so the same values): nb_adam_update reads them instead of two
// powf per parameter; a t beyond the table computes them.
constexpr uint32_t kAdamBiasTable = 1u << 16;

// One parameter group of an Adam launch (the MLP's or the grid's). The gradient of parameter i is
// grad[i] below `split`, grad_h[i] (fp16) from it on; split and n are multiples of 4.
struct AdamGroup {
    float *w, *m, *v;
    uint32_t* t;
    __half* wh;
    const float* grad;
    const __half* grad_h;
    uint32_t split, n;
    GpuAdamRule r;
};

// dst = fp16(src), n values.
void launch_to_half(const float* src, __half* dst, uint32_t n, cudaStream_t s);
// Blocks of launch_stats for a batch of n: the number of 6-double loss partials it writes.
int stats_blocks(uint32_t n);
// Per-leaf sample counts and fixed-point loss sums of cuts[0] (into copy 0 of the counters, which the
// caller zeroed, all copies) and per-block partial sums of the loss terms and hits.
void launch_stats(const DevBatch& b, uint32_t leaves, uint32_t* leaf_samples,
                  unsigned long long* leaf_loss_fx, double* partials, cudaStream_t s);
// The MLP gradient = sum of the fused MLP's per-block slices (slice_count of them) in block order, checked;
// the fp16 grid gradient's values [first, n) checked (first, n: multiples of 8; n == first: none). A
// non-finite value sets NB_GUARD_GRADIENT in *flag.
void launch_reduce_check(const float* slices, int slice_count, float* mlp_grad, const __half* grid_grad_h,
                         uint32_t first, uint32_t n, uint32_t* flag, cudaStream_t s);
// The deterministic mode's grid gradient: fixed-point sums converted to fp32 and checked.
void launch_check_grid(float* grad, const unsigned long long* fx, uint32_t n, uint32_t* flag, cudaStream_t s);
// Fills the two kAdamBiasTable-entry tables.
void launch_adam_bias_tables(float beta1, float beta2, float* bias_sqrt, float* bias_div, cudaStream_t s);
// Adam over both groups (one launch) on the summed gradient x scale_inv / *valid; nothing when *flag != 0
// or *valid == 0.
void launch_adam(const AdamGroup& mlp, const AdamGroup& grid, float scale_inv, const float* bias_sqrt,
                 const float* bias_div, const uint32_t* flag, const uint32_t* valid, cudaStream_t s);

} // namespace nbvh::cuda
