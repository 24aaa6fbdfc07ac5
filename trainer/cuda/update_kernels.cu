// Kernels of a training step after the grid backward: per-leaf statistics, the MLP gradient's reduction,
// the non-finite guard's checks, Adam (update_kernels.cuh).
#include "trainer/cuda/update_kernels.cuh"

namespace nbvh::cuda {
namespace {

constexpr int kStatsThreads = 256;

__global__ void k_to_half(const float* src, __half* dst, uint32_t n) {
    const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) dst[i] = __float2half_rn(src[i]);
}

// Per-leaf statistics (cuts[0]) and per-block partial sums of the loss terms (fixed reduction order).
__global__ void k_stats(DevBatch b, uint32_t leaves, uint32_t* leaf_samples, unsigned long long* leaf_loss_fx,
                        double* partials) {
    __shared__ double red[6][kStatsThreads];
    const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    const size_t copy = size_t(blockIdx.x % kLeafCopies) * leaves;
    leaf_samples += copy;
    leaf_loss_fx += copy;
    double v[6] = {0, 0, 0, 0, 0, 0};
    if (i < b.n && b.leaf[i] >= 0) {
        for (int q = 0; q < 5; ++q) v[q] = b.loss[5 * size_t(i) + q];
        v[5] = b.target[8 * size_t(i)] > 0.5f ? 1.0 : 0.0;
        if (b.cut[i] == 0) {
            atomicAdd(&leaf_samples[b.leaf[i]], 1u);
            atomicAdd(&leaf_loss_fx[b.leaf[i]], (unsigned long long)__double2ll_rn(v[4] * 4294967296.0));
        }
    }
    for (int q = 0; q < 6; ++q) red[q][threadIdx.x] = v[q];
    __syncthreads();
    for (int s = kStatsThreads / 2; s > 0; s >>= 1) {
        if (int(threadIdx.x) < s)
            for (int q = 0; q < 6; ++q) red[q][threadIdx.x] += red[q][threadIdx.x + s];
        __syncthreads();
    }
    if (threadIdx.x == 0)
        for (int q = 0; q < 6; ++q) partials[blockIdx.x * 6 + q] = red[q][0];
}

// Copy 0 of the per-leaf counters += copies 1.. (integer sums: the same totals in any order).
__global__ void k_fold_leaf_stats(uint32_t leaves, uint32_t* leaf_samples, unsigned long long* leaf_loss_fx) {
    const uint32_t l = blockIdx.x * blockDim.x + threadIdx.x;
    if (l >= leaves) return;
    uint32_t n = 0;
    unsigned long long fx = 0;
    for (uint32_t k = 0; k < kLeafCopies; ++k) {
        n += leaf_samples[size_t(k) * leaves + l];
        fx += leaf_loss_fx[size_t(k) * leaves + l];
    }
    leaf_samples[l] = n;
    leaf_loss_fx[l] = fx;
}

// MLP gradient = sum of the per-block slices in block order (deterministic), checked for finiteness
// (blocks [0, reduce_blocks)); the fast mode's fp16 grid gradient (fine levels, [first, n), 8 values per
// thread) checked too, as fp16 sums can overflow (the other blocks). One launch for both.
__global__ void k_reduce_check(const float* slices, int slice_count, float* grad, uint32_t reduce_blocks,
                               const __half* grad_h, uint32_t first, uint32_t n, uint32_t* flag) {
    if (blockIdx.x < reduce_blocks) {
        const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
        if (i >= NB_MLP_WEIGHT_COUNT) return;
        float s = 0.0f;
        for (int k = 0; k < slice_count; ++k) s += slices[size_t(k) * NB_MLP_WEIGHT_COUNT + i];
        grad[i] = s;
        if (!isfinite(s)) atomicOr(flag, NB_GUARD_GRADIENT);
        return;
    }
    const uint32_t i = first + 8u * ((blockIdx.x - reduce_blocks) * blockDim.x + threadIdx.x);
    if (i >= n) return;
    const uint4 q = *reinterpret_cast<const uint4*>(grad_h + i); // first, n: multiples of 8
    // An fp16 value is inf or NaN exactly when its exponent bits are all set.
    bool bad = false;
    for (const uint32_t w : {q.x, q.y, q.z, q.w})
        bad = bad || (w & 0x7C00u) == 0x7C00u || (w & 0x7C000000u) == 0x7C000000u;
    if (bad) atomicOr(flag, NB_GUARD_GRADIENT);
}

// Grid gradient of the deterministic mode: converts the fixed-point sums and checks them (the fast mode's
// are guarded by the grid backward kernels and k_reduce_check, see cuda_core.cu step()).
__global__ void k_check_grid(float* grad, const unsigned long long* fx, uint32_t n, uint32_t* flag) {
    const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) return;
    const float g = float(double((long long)fx[i]) * (1.0 / double(NB_CUDA_FIXED_SCALE)));
    grad[i] = g;
    if (!isfinite(g)) atomicOr(flag, NB_GUARD_GRADIENT);
}

// Adam's bias-correction factors for steps t < kAdamBiasTable, by the functions k_adam would call.
__global__ void k_adam_bias_tables(float beta1, float beta2, float* bias_sqrt, float* bias_div) {
    const uint32_t t = blockIdx.x * blockDim.x + threadIdx.x;
    if (t >= kAdamBiasTable) return;
    bias_sqrt[t] = nb_adam_bias_sqrt(beta2, t);
    bias_div[t] = nb_adam_bias_div(beta1, t);
}

// Parameters 4q .. 4q + 3 of group g: nb_adam_update of engine/neural/shared/adam_update.h, the CPU's
// update, on the batch-mean gradient (summed gradient x scale), then the fp16 copy. 16-byte accesses;
// the gradient is read first, so a quad whose gradients are all 0 (skipped grid entries) reads nothing
// else. A quad with some skipped parameters writes their unchanged values back.
__device__ inline void adam_quad(const AdamGroup& g, uint32_t q, float scale, const float* bias_sqrt,
                                 const float* bias_div) {
    const uint32_t i = 4u * q;
    if (i >= g.n) return;
    float gr[4];
    if (i < g.split) {
        const float4 x = *reinterpret_cast<const float4*>(g.grad + i);
        gr[0] = x.x;
        gr[1] = x.y;
        gr[2] = x.z;
        gr[3] = x.w;
    } else {
        const uint2 x = *reinterpret_cast<const uint2*>(g.grad_h + i);
        const float2 lo = __half22float2(*reinterpret_cast<const __half2*>(&x.x));
        const float2 hi = __half22float2(*reinterpret_cast<const __half2*>(&x.y));
        gr[0] = lo.x;
        gr[1] = lo.y;
        gr[2] = hi.x;
        gr[3] = hi.y;
    }
    if (g.r.skip_zero != 0u && gr[0] == 0.0f && gr[1] == 0.0f && gr[2] == 0.0f && gr[3] == 0.0f) return;
    float4 w = *reinterpret_cast<const float4*>(g.w + i);
    float4 m = *reinterpret_cast<const float4*>(g.m + i);
    float4 v = *reinterpret_cast<const float4*>(g.v + i);
    uint4 t = *reinterpret_cast<const uint4*>(g.t + i);
    float* pw[4] = {&w.x, &w.y, &w.z, &w.w};
    float* pm[4] = {&m.x, &m.y, &m.z, &m.w};
    float* pv[4] = {&v.x, &v.y, &v.z, &v.w};
    uint32_t* pt[4] = {&t.x, &t.y, &t.z, &t.w};
#pragma unroll
    for (int k = 0; k < 4; ++k)
        nb_adam_update(*pw[k], *pm[k], *pv[k], *pt[k], gr[k] * scale, g.r, bias_sqrt, bias_div,
                       kAdamBiasTable);
    *reinterpret_cast<float4*>(g.w + i) = w;
    *reinterpret_cast<float4*>(g.m + i) = m;
    *reinterpret_cast<float4*>(g.v + i) = v;
    *reinterpret_cast<uint4*>(g.t + i) = t;
    const __half2 h0 = __floats2half2_rn(w.x, w.y), h1 = __floats2half2_rn(w.z, w.w);
    uint2 h;
    h.x = *reinterpret_cast<const uint32_t*>(&h0);
    h.y = *reinterpret_cast<const uint32_t*>(&h1);
    *reinterpret_cast<uint2*>(g.wh + i) = h;
}

// tcnn Adam over both parameter groups in one launch (blocks [0, a_blocks) group a, the rest group b),
// per-parameter step counters and the sparse skip of zero grid gradients (adam_update.h), on the summed
// gradient / (loss scale x trained samples). Does nothing when the guard flag is set or no sample was
// trained.
constexpr uint32_t kAdamThreads = 256;
__global__ void __launch_bounds__(kAdamThreads)
    k_adam(AdamGroup a, AdamGroup b, uint32_t a_blocks, float scale_inv, const float* bias_sqrt,
           const float* bias_div, const uint32_t* flag, const uint32_t* valid) {
    if (*flag != 0u || *valid == 0u) return;
    const float scale = scale_inv / float(*valid);
    if (blockIdx.x < a_blocks)
        adam_quad(a, blockIdx.x * kAdamThreads + threadIdx.x, scale, bias_sqrt, bias_div);
    else
        adam_quad(b, (blockIdx.x - a_blocks) * kAdamThreads + threadIdx.x, scale, bias_sqrt, bias_div);
}
uint32_t adam_blocks(uint32_t n) { return (n / 4u + kAdamThreads - 1u) / kAdamThreads; }
static_assert(NB_MLP_WEIGHT_COUNT % 4u == 0u, "k_adam takes the MLP's parameters four at a time");

} // namespace

void launch_to_half(const float* src, __half* dst, uint32_t n, cudaStream_t s) {
    k_to_half<<<(n + 255) / 256, 256, 0, s>>>(src, dst, n);
    NBVH_CUDA_CHECK(cudaGetLastError());
}

int stats_blocks(uint32_t n) { return int((n + kStatsThreads - 1) / kStatsThreads); }

void launch_stats(const DevBatch& b, uint32_t leaves, uint32_t* leaf_samples,
                  unsigned long long* leaf_loss_fx, double* partials, cudaStream_t s) {
    k_stats<<<stats_blocks(b.n), kStatsThreads, 0, s>>>(b, leaves, leaf_samples, leaf_loss_fx, partials);
    if (leaves > 0)
        k_fold_leaf_stats<<<(leaves + 255) / 256, 256, 0, s>>>(leaves, leaf_samples, leaf_loss_fx);
    NBVH_CUDA_CHECK(cudaGetLastError());
}

void launch_reduce_check(const float* slices, int slice_count, float* mlp_grad, const __half* grid_grad_h,
                         uint32_t first, uint32_t n, uint32_t* flag, cudaStream_t s) {
    const uint32_t reduce_blocks = (NB_MLP_WEIGHT_COUNT + 255) / 256;
    const uint32_t fine = n - first;
    k_reduce_check<<<reduce_blocks + (fine / 8u + 255u) / 256u, 256, 0, s>>>(
        slices, slice_count, mlp_grad, reduce_blocks, grid_grad_h, first, n, flag);
    NBVH_CUDA_CHECK(cudaGetLastError());
}

void launch_check_grid(float* grad, const unsigned long long* fx, uint32_t n, uint32_t* flag,
                       cudaStream_t s) {
    k_check_grid<<<(n + 255) / 256, 256, 0, s>>>(grad, fx, n, flag);
    NBVH_CUDA_CHECK(cudaGetLastError());
}

void launch_adam_bias_tables(float beta1, float beta2, float* bias_sqrt, float* bias_div, cudaStream_t s) {
    k_adam_bias_tables<<<kAdamBiasTable / 256, 256, 0, s>>>(beta1, beta2, bias_sqrt, bias_div);
    NBVH_CUDA_CHECK(cudaGetLastError());
}

void launch_adam(const AdamGroup& mlp, const AdamGroup& grid, float scale_inv, const float* bias_sqrt,
                 const float* bias_div, const uint32_t* flag, const uint32_t* valid, cudaStream_t s) {
    const uint32_t mlp_blocks = adam_blocks(mlp.n);
    k_adam<<<mlp_blocks + adam_blocks(grid.n), kAdamThreads, 0, s>>>(mlp, grid, mlp_blocks, scale_inv,
                                                                     bias_sqrt, bias_div, flag, valid);
    NBVH_CUDA_CHECK(cudaGetLastError());
}

} // namespace nbvh::cuda
