// The network part of a training step (paper §4): hash-grid encoding of the 3 segment points
// (fp16 features, shared/hashgrid.h), the fully fused MLP forward + loss + backward on tensor cores
// (WMMA 16x16x16, fp16 inputs, fp32 accumulation, activations kept in shared memory per 128-sample
// tile), and the grid backward (scatter to the 8 corners of every level).
//
// MLP kernel layout (one block = 8 warps = 128 samples per tile, persistent over tiles):
//   shared: W (fp16, 19456 in rows padded to 21632: w_ld), X0 (128 x 96), H1..H4 (128 x 64; H_{m+1} is
//   overwritten by dZ_m once dW_{m+1} has consumed it), dZ4 (128 x 16), per-warp fp32 staging (16 x 64).
//   Forward and the data path of the backward are warp-local (16 samples each); weight gradients
//   dW_m = dZ_m^T X_m use K = 128 (the whole tile) and accumulate into the block's own fp32 slice in
//   global memory (L2-resident); slices are summed in a fixed order afterwards, so MLP gradients are
//   deterministic without atomics.
#include <mma.h>

#include "trainer/cuda/device_common.cuh"

namespace nbvh::cuda {
namespace {
using namespace nvcuda;

constexpr int kWarps = 8;
constexpr int kTile = 16 * kWarps; // samples per block tile
constexpr int kLdIn = NB_MLP_INPUTS + 8;  // 104 halves (padding against bank conflicts)
constexpr int kLdH = NB_MLP_WIDTH + 8;    // 72
constexpr int kLdO = 16 + 8;              // 24
constexpr int kLdS = 16 + 4;              // 20 floats (per-warp 16 x 16 fp32 staging)

// The weights in shared memory, each matrix W_m row-major (outputs x inputs) with its rows padded by 8
// halves: a row stride of 128 or 192 bytes put the 8 rows of every ldmatrix on the same banks (ncu on
// the H200: 71 % of k_mlp's shared-memory wavefronts were bank-conflict replays).
__host__ __device__ constexpr int w_ld(int m) { return int(m == 0 ? NB_MLP_INPUTS : NB_MLP_WIDTH) + 8; }
__host__ __device__ constexpr int w_rows(int m) {
    return m == int(NB_MLP_HIDDEN_LAYERS) ? int(NB_MLP_OUTPUTS_PADDED) : int(NB_MLP_WIDTH);
}
__host__ __device__ constexpr int w_offset(int m) {
    return m == 0 ? 0 : w_offset(m - 1) + w_rows(m - 1) * w_ld(m - 1);
}
constexpr size_t kSmemW = size_t(w_offset(int(NB_MLP_HIDDEN_LAYERS) + 1)) * 2;
static_assert(w_offset(1) % 16 == 0 && w_offset(2) % 16 == 0 && w_offset(4) % 16 == 0 && kSmemW % 128 == 0,
              "wmma tiles need 32-byte aligned starts");
constexpr size_t kSmemX0 = size_t(kTile) * kLdIn * 2;
constexpr size_t kSmemH = size_t(kTile) * kLdH * 2;
constexpr size_t kSmemO = size_t(kTile) * kLdO * 2;
constexpr size_t kSmemS = size_t(kWarps) * 16 * kLdS * 4;
constexpr size_t kSmemTotal = kSmemW + kSmemX0 + 4 * kSmemH + kSmemO + kSmemS;

// ---------------------------------------------------------------------------------------------
// Grid forward: one thread per (sample, point, level).
// 32 registers (8 blocks of 256 per SM, as before the paired loads; unbounded, nvcc gives it 40). The
// SMs of sm_86 / sm_87 / sm_89 hold 1,536 threads: 6 blocks there (38 registers; not measured there).
#if defined(__CUDA_ARCH__) && (__CUDA_ARCH__ == 860 || __CUDA_ARCH__ == 870 || __CUDA_ARCH__ == 890)
constexpr int kEncodeBlocksPerSm = 6;
#else
constexpr int kEncodeBlocksPerSm = 8;
#endif
__global__ void __launch_bounds__(256, kEncodeBlocksPerSm) k_encode(DevNetwork net, DevBatch b) {
    const uint32_t tid = blockIdx.x * blockDim.x + threadIdx.x;
    const uint32_t per = NB_SEGMENT_POINTS * NB_GRID_MAX_LEVELS;
    if (tid >= b.n * per) return;
    const uint32_t i = tid / per, r = tid % per, k = r / NB_GRID_MAX_LEVELS, l = r % NB_GRID_MAX_LEVELS;
    __half2 out[2];
    if (b.leaf[i] < 0) {
        out[0] = out[1] = __floats2half2_rn(0.0f, 0.0f);
    } else {
        const float* pp = b.points + 9 * size_t(i) + 3 * k;
        const vec3 p(pp[0], pp[1], pp[2]);
        const GpuHashLevel lv = net.levels[l];
        uvec3 cell;
        vec3 frac;
        nb_grid_position(lv, p, cell, frac);
        float acc[4] = {0, 0, 0, 0};
        auto add = [&](uint32_t c, uint2 raw) {
            const float w = nb_grid_corner_weight(frac, c);
            const __half2 a = *reinterpret_cast<const __half2*>(&raw.x);
            const __half2 bb = *reinterpret_cast<const __half2*>(&raw.y);
            const float2 fa = __half22float2(a), fb = __half22float2(bb);
            acc[0] += w * fa.x;
            acc[1] += w * fa.y;
            acc[2] += w * fb.x;
            acc[3] += w * fb.y;
        };
        // Corners c and c + 1 (x and x + 1) by pairs. Where their entries differ only in bit 0 (hashed
        // levels for even x: x * 1 ^ ...; dense levels at an even index) both lie in one 16-byte-aligned
        // pair of entries (level offsets and sizes are even, checked at upload): one 16-byte load serves
        // both, else the second corner takes its own 8-byte load. The random gathers are bound by the
        // number of requests, not bytes (results/neural/README.md): a quarter fewer. Same values, same
        // order of the sum. H200: encode 0.201 -> 0.168 ms per 2^18 samples (results/cuda_training.md);
        // the render kernels' lane pairs (each lane loads one corner of a pair) measured 0.28 ms here.
        const uint2* grid2 = reinterpret_cast<const uint2*>(net.grid_h);
        for (uint32_t c = 0; c < NB_GRID_CORNERS; c += 2) {
            const uint32_t e0 = nb_grid_corner_entry(lv, cell, c), e1 = nb_grid_corner_entry(lv, cell, c + 1);
            const uint4 q = __ldg(reinterpret_cast<const uint4*>(net.grid_h) + (e0 >> 1));
            const bool odd = (e0 & 1u) != 0u;
            add(c, odd ? make_uint2(q.z, q.w) : make_uint2(q.x, q.y));
            add(c + 1,
                (e0 ^ e1) == 1u ? (odd ? make_uint2(q.x, q.y) : make_uint2(q.z, q.w)) : __ldg(grid2 + e1));
        }
        out[0] = __floats2half2_rn(acc[0], acc[1]);
        out[1] = __floats2half2_rn(acc[2], acc[3]);
    }
    *reinterpret_cast<uint2*>(b.features + size_t(i) * NB_MLP_INPUTS + nb_feature_slot(k, l, 0)) =
        *reinterpret_cast<const uint2*>(out);
}

// ---------------------------------------------------------------------------------------------
// Grid backward of the coarse levels (fast mode): their few entries receive thousands of adds per step,
// which serialise in L2 as global atomics. Each block accumulates its share of the samples in shared
// memory and flushes one global float4 add per touched entry.
// Which levels are coarse: those whose values would fit this many bytes as fp32 (levels 0-1 of the paper
// configuration; the fp16 accumulator uses half of it).
constexpr uint32_t kCoarseSmemBytes = 96 * 1024;
// The coarse-level backward of one (sample, level): each of the segment's points adds w_c * dL/dfeatures
// to the 8 corners of its cell in the block's shared accumulator. Points in the same cell (a ray
// segment's 3 points usually share the coarse levels' cells) are summed in registers first, so the
// (two half2) shared atomics run once per distinct (cell, corner): up to 3x fewer. Non-finite
// gradients raise the guard. Not used on the fine levels (k_grid_backward,
// one thread per point): there the points rarely share a cell and the merged form measured 1 % slower
// (H200, results/cuda_training.md).
// The accumulator holds fp16 pairs, pair-major (features 0-1 of entry e at e, features 2-3 at entries +
// e): two half2 shared atomics per corner instead of four float ones, each block's partial sums rounded
// to fp16 (a block adds a few dozen terms per entry; the flush adds the blocks' partials in fp32 and
// raises the guard on one that overflowed). H200: grid backward 0.423 -> 0.399 ms, the gradient against
// the CPU reference 2.700e-3 -> 2.708e-3 (results/cuda_training.md). With the 4 features of an entry in
// consecutive words the lanes' random entries fell on 8 bank groups (ncu: 44 % of the kernel's shared
// wavefronts were conflict replays), hence the pair-major layout.
__device__ void coarse_backward_sample_level(const GpuHashLevel& lv, const DevBatch& b, uint32_t i,
                                             uint32_t l, uint32_t* flag, __half2* acc_h, uint32_t entries) {
    uvec3 cell[NB_SEGMENT_POINTS];
    vec3 frac[NB_SEGMENT_POINTS];
    float4 df[NB_SEGMENT_POINTS];
    bool live[NB_SEGMENT_POINTS];
    for (uint32_t k = 0; k < NB_SEGMENT_POINTS; ++k) {
        df[k] = *reinterpret_cast<const float4*>(b.dfeatures + size_t(i) * NB_MLP_INPUTS + nb_feature_slot(k, l, 0));
        const bool finite = isfinite(df[k].x + df[k].y + df[k].z + df[k].w);
        if (!finite) atomicOr(flag, NB_GUARD_GRADIENT);
        live[k] = finite && (df[k].x != 0.0f || df[k].y != 0.0f || df[k].z != 0.0f || df[k].w != 0.0f);
        const float* pp = b.points + 9 * size_t(i) + 3 * k;
        nb_grid_position(lv, vec3(pp[0], pp[1], pp[2]), cell[k], frac[k]);
    }
    auto same = [&](uint32_t j, uint32_t k) {
        return cell[j].x == cell[k].x && cell[j].y == cell[k].y && cell[j].z == cell[k].z;
    };
    for (uint32_t k = 0; k < NB_SEGMENT_POINTS; ++k) {
        if (!live[k]) continue;
        bool merged = false; // into an earlier point of the same cell
        for (uint32_t j = 0; j < k; ++j) merged |= live[j] && same(j, k);
        if (merged) continue;
        for (uint32_t c = 0; c < NB_GRID_CORNERS; ++c) {
            float4 v = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
            for (uint32_t j = k; j < NB_SEGMENT_POINTS; ++j) {
                if (!live[j] || !same(j, k)) continue;
                const float w = nb_grid_corner_weight(frac[j], c);
                v.x += w * df[j].x;
                v.y += w * df[j].y;
                v.z += w * df[j].z;
                v.w += w * df[j].w;
            }
            __half2* dst = acc_h + nb_grid_corner_entry(lv, cell[k], c); // coarse levels start at entry 0
            atomicAdd(dst, __floats2half2_rn(v.x, v.y));
            atomicAdd(dst + entries, __floats2half2_rn(v.z, v.w));
        }
    }
}

// 2 blocks of 512 per SM: 64 registers (24 bytes spilled; unbounded, nvcc gives it 72, one block per SM,
// and the kernel ran 0.44 instead of 0.40 ms).
__global__ void __launch_bounds__(512, 2)
    k_grid_backward_coarse(DevNetwork net, DevBatch b, uint32_t coarse_levels, uint32_t coarse_values,
                           uint32_t* flag) {
    extern __shared__ __half2 acc_h[];
    for (uint32_t v = threadIdx.x; v < coarse_values / 2; v += blockDim.x)
        acc_h[v] = __floats2half2_rn(0.0f, 0.0f);
    __syncthreads();
    // One thread per (sample, coarse level); the shared-memory atomics bound this kernel
    // (results/cuda_training.md), and merging the points of one cell cuts them by up to 3x.
    const uint32_t items = b.n * coarse_levels, entries = coarse_values / 4;
    for (uint32_t t = blockIdx.x * blockDim.x + threadIdx.x; t < items; t += gridDim.x * blockDim.x) {
        const uint32_t i = t / coarse_levels, l = t % coarse_levels;
        if (b.leaf[i] < 0) continue;
        coarse_backward_sample_level(net.levels[l], b, i, l, flag, acc_h, entries);
    }
    __syncthreads();
    // One float4 add per touched entry (coarse levels start at entry 0; coarse_values is a multiple of 4).
    for (uint32_t e = threadIdx.x; e < entries; e += blockDim.x) {
        const float2 lo = __half22float2(acc_h[e]), hi = __half22float2(acc_h[e + entries]);
        const float4 v = make_float4(lo.x, lo.y, hi.x, hi.y);
        if (v.x == 0.0f && v.y == 0.0f && v.z == 0.0f && v.w == 0.0f) continue;
        if (!isfinite(v.x + v.y + v.z + v.w)) atomicOr(flag, NB_GUARD_GRADIENT); // an fp16 partial overflowed
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ >= 900
        atomicAdd(reinterpret_cast<float4*>(net.grid_grad) + e, v);
#else
        float* dst = net.grid_grad + size_t(e) * 4;
        atomicAdd(dst + 0, v.x);
        atomicAdd(dst + 1, v.y);
        atomicAdd(dst + 2, v.z);
        atomicAdd(dst + 3, v.w);
#endif
    }
}

// fp16 pair (x in the low half) of two floats, round to nearest, as bits.
__device__ inline uint32_t h2_bits(float x, float y) {
    const __half2 h = __floats2half2_rn(x, y);
    return *reinterpret_cast<const uint32_t*>(&h);
}
// Vector reductions of fp16 pairs in global memory (sm_90: red.global.add.noftz.v{2,4}.f16x2; no flush
// to zero). Earlier architectures add the pairs with half2 atomics.
__device__ inline void red_v2_f16x2(__half* dst, uint32_t a, uint32_t b) {
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ >= 900
    asm volatile("red.global.add.noftz.v2.f16x2 [%0], {%1, %2};" ::"l"(dst), "r"(a), "r"(b) : "memory");
#else
    atomicAdd(reinterpret_cast<__half2*>(dst), *reinterpret_cast<const __half2*>(&a));
    atomicAdd(reinterpret_cast<__half2*>(dst) + 1, *reinterpret_cast<const __half2*>(&b));
#endif
}
__device__ inline void red_v4_f16x2(__half* dst, uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ >= 900
    asm volatile("red.global.add.noftz.v4.f16x2 [%0], {%1, %2, %3, %4};" ::"l"(dst), "r"(a), "r"(b), "r"(c),
                 "r"(d)
                 : "memory");
#else
    red_v2_f16x2(dst, a, b);
    red_v2_f16x2(dst + 4, c, d);
#endif
}

// Grid backward: one thread per (sample, point, level >= first_level), 8 corners x 4 features. Levels below
// `first_level` were done by k_grid_backward_coarse (threads are mapped to the remaining levels only, so no
// warp lane idles on them).
// 40 registers (6 blocks of 256 per SM; held to 32, it spilled and ran 1.5 % slower, H200).
__global__ void k_grid_backward(DevNetwork net, DevBatch b, int deterministic, uint32_t first_level, uint32_t* flag) {
    const uint32_t tid = blockIdx.x * blockDim.x + threadIdx.x;
    const uint32_t levels = NB_GRID_MAX_LEVELS - first_level, per = NB_SEGMENT_POINTS * levels;
    if (tid >= b.n * per) return;
    const uint32_t i = tid / per, r = tid % per, k = r / levels, l = first_level + r % levels;
    if (b.leaf[i] < 0) return;
    const float4 df = *reinterpret_cast<const float4*>(b.dfeatures + size_t(i) * NB_MLP_INPUTS + nb_feature_slot(k, l, 0));
    if (!isfinite(df.x + df.y + df.z + df.w)) { atomicOr(flag, NB_GUARD_GRADIENT); return; }
    if (df.x == 0.0f && df.y == 0.0f && df.z == 0.0f && df.w == 0.0f) return;
    const float* pp = b.points + 9 * size_t(i) + 3 * k;
    const vec3 p(pp[0], pp[1], pp[2]);
    const GpuHashLevel lv = net.levels[l];
    uvec3 cell;
    vec3 frac;
    nb_grid_position(lv, p, cell, frac);
    if (deterministic) {
        for (uint32_t c = 0; c < NB_GRID_CORNERS; ++c) {
            const float w = nb_grid_corner_weight(frac, c);
            const uint32_t e = nb_grid_corner_entry(lv, cell, c);
            // Integer addition is associative: the sum does not depend on the atomics' order.
            unsigned long long* dst = net.grid_grad_fx + size_t(e) * 4;
            atomicAdd(dst + 0, (unsigned long long)llrintf(w * df.x * NB_CUDA_FIXED_SCALE));
            atomicAdd(dst + 1, (unsigned long long)llrintf(w * df.y * NB_CUDA_FIXED_SCALE));
            atomicAdd(dst + 2, (unsigned long long)llrintf(w * df.z * NB_CUDA_FIXED_SCALE));
            atomicAdd(dst + 3, (unsigned long long)llrintf(w * df.w * NB_CUDA_FIXED_SCALE));
        }
        return;
    }
    // Fast mode: fp16 vector reductions, as tiny-cuda-nn accumulates its grid gradients (notes tiny-cuda-nn
    // §B; it issues two half2 atomics per corner). Corners x and x + 1 whose entries share a 16-byte-aligned
    // pair (entries differing only in bit 0, as in k_encode) take one 16-byte reduction for both; the
    // others one 8-byte reduction each. The L2 serves these at a rate of requests (results/cuda_training.md
    // bench_l2_reductions): fewer requests than one float4 per corner.
    for (uint32_t c = 0; c < NB_GRID_CORNERS; c += 2) {
        const uint32_t e0 = nb_grid_corner_entry(lv, cell, c), e1 = nb_grid_corner_entry(lv, cell, c + 1);
        const float w0 = nb_grid_corner_weight(frac, c), w1 = nb_grid_corner_weight(frac, c + 1);
        const uint32_t a0 = h2_bits(w0 * df.x, w0 * df.y), b0 = h2_bits(w0 * df.z, w0 * df.w);
        const uint32_t a1 = h2_bits(w1 * df.x, w1 * df.y), b1 = h2_bits(w1 * df.z, w1 * df.w);
        if ((e0 ^ e1) == 1u) {
            const bool odd = (e0 & 1u) != 0u; // the pair's first entry is e1
            __half* dst = net.grid_grad_h + size_t(e0 & ~1u) * 4;
            if (odd)
                red_v4_f16x2(dst, a1, b1, a0, b0);
            else
                red_v4_f16x2(dst, a0, b0, a1, b1);
        } else {
            red_v2_f16x2(net.grid_grad_h + size_t(e0) * 4, a0, b0);
            red_v2_f16x2(net.grid_grad_h + size_t(e1) * 4, a1, b1);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Fused MLP.
using FragA = wmma::fragment<wmma::matrix_a, 16, 16, 16, __half, wmma::row_major>;
using FragAc = wmma::fragment<wmma::matrix_a, 16, 16, 16, __half, wmma::col_major>;
using FragBc = wmma::fragment<wmma::matrix_b, 16, 16, 16, __half, wmma::col_major>;
using FragBr = wmma::fragment<wmma::matrix_b, 16, 16, 16, __half, wmma::row_major>;
using FragC = wmma::fragment<wmma::accumulator, 16, 16, 16, float>;
using FragCh = wmma::fragment<wmma::accumulator, 16, 16, 16, __half>;
// ReLU, the fp16 rounding and the ReLU mask are applied on the accumulator fragments in registers: element
// i of an fp32 and of an fp16 accumulator fragment is the same matrix element (both are the m16n8k16 C
// layout on sm_70+), which the CPU cross-check of every activation and gradient (tests/cuda) verifies.
static_assert(int(FragC::num_elements) == int(FragCh::num_elements), "accumulator fragments must match");

// H(16 x 64) = fp16(relu(X(16 x 16*KT) W_m^T)) for one warp (rounding point R3 of mlp.h), stored as fp16.
// The A fragments of the warp's rows are loaded once and reused for the 4 output column tiles.
template <int KT>
__device__ void layer_forward_relu(const __half* x, int ldx, const __half* w, int ldw, __half* out) {
    FragA a[KT];
#pragma unroll
    for (int kk = 0; kk < KT; ++kk) wmma::load_matrix_sync(a[kk], x + kk * 16, ldx);
#pragma unroll
    for (int j = 0; j < 4; ++j) {
        FragC acc;
        wmma::fill_fragment(acc, 0.0f);
#pragma unroll
        for (int kk = 0; kk < KT; ++kk) {
            FragBc bm;
            wmma::load_matrix_sync(bm, w + size_t(j) * 16 * ldw + kk * 16, ldw); // W^T as col-major
            wmma::mma_sync(acc, a[kk], bm, acc);
        }
        FragCh h;
#pragma unroll
        for (int e = 0; e < FragC::num_elements; ++e) h.x[e] = __float2half_rn(fmaxf(acc.x[e], 0.0f));
        wmma::store_matrix_sync(out + j * 16, h, kLdH, wmma::mem_row_major);
    }
}

// dX(16 x 16*NJ) = dZ(16 x 16*KT) W_m (16*KT x 16*NJ) for one warp, into registers. W_m row-major, row
// stride ldw.
template <int KT, int NJ>
__device__ void layer_backward_data(const __half* dz, int lddz, const __half* w, int ldw, FragC (&out)[NJ]) {
    FragA a[KT];
#pragma unroll
    for (int kk = 0; kk < KT; ++kk) wmma::load_matrix_sync(a[kk], dz + kk * 16, lddz);
#pragma unroll
    for (int j = 0; j < NJ; ++j) {
        wmma::fill_fragment(out[j], 0.0f);
#pragma unroll
        for (int kk = 0; kk < KT; ++kk) {
            FragBr bm;
            wmma::load_matrix_sync(bm, w + size_t(kk) * 16 * ldw + j * 16, ldw);
            wmma::mma_sync(out[j], a[kk], bm, out[j]);
        }
    }
}

// dZ_m = dX ⊙ relu'(H), in place over the warp's 16 rows of H (ReLU'(0) = 0, as tcnn), rounded to fp16.
__device__ void relu_mask_in_place(__half* hz, const FragC (&dx)[4]) {
#pragma unroll
    for (int j = 0; j < 4; ++j) {
        FragCh h;
        wmma::load_matrix_sync(h, hz + j * 16, kLdH, wmma::mem_row_major);
#pragma unroll
        for (int e = 0; e < FragC::num_elements; ++e)
            h.x[e] = __float2half_rn(__half2float(h.x[e]) > 0.0f ? dx[j].x[e] : 0.0f);
        wmma::store_matrix_sync(hz + j * 16, h, kLdH, wmma::mem_row_major);
    }
}

// Weight gradient tiles of one warp: dW_m[tr, tc0 .. tc0+TPW) += dZ^T (16 x 128) X (128 x 16*TPW), K = the whole
// tile. The accumulators stay in registers across all tiles of the block (a fixed order: deterministic).
template <int TPW>
__device__ void weight_grad(const __half* dz, int lddz, const __half* x, int ldx, int tr, int tc0, FragC (&acc)[TPW]) {
#pragma unroll 2
    for (int kk = 0; kk < kTile / 16; ++kk) {
        FragAc a;
        wmma::load_matrix_sync(a, dz + size_t(kk) * 16 * lddz + tr * 16, lddz); // dZ^T: col-major view
#pragma unroll
        for (int q = 0; q < TPW; ++q) {
            FragBr bm;
            wmma::load_matrix_sync(bm, x + size_t(kk) * 16 * ldx + (tc0 + q) * 16, ldx);
            wmma::mma_sync(acc[q], a, bm, acc[q]);
        }
    }
}

template <int TPW>
__device__ void store_weight_grad(float* dst, int cols, int tr, int tc0, FragC (&acc)[TPW]) {
#pragma unroll
    for (int q = 0; q < TPW; ++q)
        wmma::store_matrix_sync(dst + size_t(tr) * 16 * cols + (tc0 + q) * 16, acc[q], cols, wmma::mem_row_major);
}

static_assert(NB_MLP_INPUTS == 96 && NB_MLP_WIDTH == 64 && NB_MLP_HIDDEN_LAYERS == 4 && kWarps == 8,
              "k_mlp's warp-to-tile assignment is written for 96 -> 64x4 -> 16 and 8 warps");

__global__ void __launch_bounds__(kWarps * 32, 1)
k_mlp(DevNetwork net, DevBatch b, LossParams lp, float* slices, uint32_t* flag) {
    extern __shared__ __align__(128) unsigned char smem[];
    __half* sW = reinterpret_cast<__half*>(smem);
    __half* sX0 = reinterpret_cast<__half*>(smem + kSmemW);
    __half* sH[4];
    for (int m = 0; m < 4; ++m) sH[m] = reinterpret_cast<__half*>(smem + kSmemW + kSmemX0 + m * kSmemH);
    __half* sO = reinterpret_cast<__half*>(smem + kSmemW + kSmemX0 + 4 * kSmemH);
    float* sS = reinterpret_cast<float*>(smem + kSmemW + kSmemX0 + 4 * kSmemH + kSmemO);

    const int warp = threadIdx.x / 32, lane = threadIdx.x % 32;
    float* stage = sS + warp * 16 * kLdS;
    float* slice = slices + size_t(blockIdx.x) * NB_MLP_WEIGHT_COUNT;

    // Weight-gradient tiles owned by this warp (fixed for the whole kernel):
    //   W0 (64 x 96 = 4 x 6 tiles): row warp/2, columns 3*(warp%2) .. +3;
    //   W1..W3 (4 x 4 tiles): row warp/2, columns 2*(warp%2) .. +2;  W4 (16 x 64 = 1 x 4 tiles): warps 0..3.
    const int tr = warp / 2, tc0_in = 3 * (warp % 2), tc0_h = 2 * (warp % 2);
    FragC g0[3], g1[2], g2[2], g3[2], g4[1];
#pragma unroll
    for (int q = 0; q < 3; ++q) wmma::fill_fragment(g0[q], 0.0f);
#pragma unroll
    for (int q = 0; q < 2; ++q) {
        wmma::fill_fragment(g1[q], 0.0f);
        wmma::fill_fragment(g2[q], 0.0f);
        wmma::fill_fragment(g3[q], 0.0f);
    }
    wmma::fill_fragment(g4[0], 0.0f);

    // The weights into their padded rows (w_ld), 8 halves at a time.
    for (int m = 0; m <= int(NB_MLP_HIDDEN_LAYERS); ++m) {
        const int row8 = int(nb_mlp_layer_inputs(uint32_t(m))) / 8;
        const uint4* src = reinterpret_cast<const uint4*>(net.mlp_h + nb_mlp_layer_offset(uint32_t(m)));
        uint4* dst = reinterpret_cast<uint4*>(sW + w_offset(m));
        for (int i = threadIdx.x; i < w_rows(m) * row8; i += blockDim.x)
            dst[(i / row8) * (w_ld(m) / 8) + i % row8] = src[i];
    }
    __syncthreads();

    const int tiles = int((b.n + kTile - 1) / kTile);
    for (int tile = blockIdx.x; tile < tiles; tile += gridDim.x) {
        const int row0 = warp * 16;                  // this warp's rows in the tile buffers
        const uint32_t s0 = uint32_t(tile) * kTile + row0; // first sample of this warp
        // Load X0 (16 x 96 halves) for this warp; samples past the batch are zero.
        for (int e = lane; e < 16 * (NB_MLP_INPUTS / 8); e += 32) {
            const int r = e / (NB_MLP_INPUTS / 8), c8 = e % (NB_MLP_INPUTS / 8);
            uint4 v = make_uint4(0, 0, 0, 0);
            if (s0 + r < b.n) v = reinterpret_cast<const uint4*>(b.features + size_t(s0 + r) * NB_MLP_INPUTS)[c8];
            *reinterpret_cast<uint4*>(sX0 + (row0 + r) * kLdIn + c8 * 8) = v;
        }
        __syncwarp();
        // Forward, hidden layers: H_{m+1} = fp16(relu(X_m W_m^T)) (rounding point R3 of mlp.h).
        layer_forward_relu<6>(sX0 + row0 * kLdIn, kLdIn, sW + w_offset(0), w_ld(0), sH[0] + row0 * kLdH);
        __syncwarp();
        for (int m = 1; m < 4; ++m) {
            layer_forward_relu<4>(sH[m - 1] + row0 * kLdH, kLdH, sW + w_offset(m), w_ld(m),
                                  sH[m] + row0 * kLdH);
            __syncwarp();
        }
        // Output layer (16 rows, 8 used): fp32 pre-activation (R4), sigmoid, loss, dZ4.
        {
            FragC acc;
            wmma::fill_fragment(acc, 0.0f);
            for (int kk = 0; kk < 4; ++kk) {
                FragA a;
                FragBc bm;
                wmma::load_matrix_sync(a, sH[3] + row0 * kLdH + kk * 16, kLdH);
                wmma::load_matrix_sync(bm, sW + w_offset(4) + kk * 16, w_ld(4));
                wmma::mma_sync(acc, a, bm, acc);
            }
            wmma::store_matrix_sync(stage, acc, kLdS, wmma::mem_row_major);
            __syncwarp();
            if (lane < 16) {
                const uint32_t si = s0 + lane;
                const bool valid = si < b.n && b.leaf[si] >= 0;
                float g[8] = {0, 0, 0, 0, 0, 0, 0, 0};
                float lv[5] = {0, 0, 0, 0, 0};
                if (valid) {
                    float y[8], t[8];
                    bool finite = true;
                    for (int o = 0; o < 8; ++o) {
                        y[o] = nb_sigmoid(stage[lane * kLdS + o]);
                        t[o] = b.target[8 * size_t(si) + o];
                        finite = finite && isfinite(y[o]);
                    }
                    if (!finite) {
                        atomicOr(flag, NB_GUARD_OUTPUT);
                    } else {
                        // The CPU's composite loss (engine/neural/shared/training_loss.h); the statistics
                        // are the unweighted terms, normal and albedo as means over their 3 channels.
                        float u[8];
                        lv[4] = nb_composite_loss(y, t, lp.loss, u, g);
                        lv[0] = u[NB_OUT_VISIBILITY];
                        lv[1] = u[NB_OUT_DEPTH];
                        lv[2] = (u[NB_OUT_NORMAL] + u[NB_OUT_NORMAL + 1] + u[NB_OUT_NORMAL + 2]) / 3.0f;
                        lv[3] = (u[NB_OUT_ALBEDO] + u[NB_OUT_ALBEDO + 1] + u[NB_OUT_ALBEDO + 2]) / 3.0f;
                        if (!isfinite(lv[4])) atomicOr(flag, NB_GUARD_OUTPUT);
                        for (int o = 0; o < 8; ++o) g[o] = nb_presigmoid_gradient(g[o], y[o]) * lp.loss_scale;
                    }
                }
                for (int o = 0; o < 16; ++o) sO[(row0 + lane) * kLdO + o] = __float2half_rn(o < 8 ? g[o] : 0.0f);
                if (si < b.n)
                    for (int q = 0; q < 5; ++q) b.loss[5 * size_t(si) + q] = lv[q];
            }
            __syncwarp();
        }
        // Backward. dX4 = dZ4 W4 (16 x 64), kept in registers.
        FragC dx[4];
        layer_backward_data<1, 4>(sO + row0 * kLdO, kLdO, sW + w_offset(4), w_ld(4), dx);
        __syncthreads();
        if (warp < 4) weight_grad<1>(sO, kLdO, sH[3], kLdH, 0, warp, g4);
        for (int m = 3; m >= 0; --m) {
            __syncthreads(); // dW_{m+1} has read H_{m+1} (= sH[m]); it now becomes dZ_m
            __half* hz = sH[m] + row0 * kLdH;
            relu_mask_in_place(hz, dx);
            __syncwarp();
            const __half* w = sW + w_offset(m);
            if (m > 0) {
                layer_backward_data<4, 4>(hz, kLdH, w, w_ld(m), dx);
            } else {
                // dL/dfeatures straight to global memory (fp32, loss-scaled), rows past the batch skipped.
                FragC dxin[6];
                layer_backward_data<4, 6>(hz, kLdH, w, w_ld(0), dxin);
                float* out = b.dfeatures + size_t(s0) * NB_MLP_INPUTS;
                if (s0 + 16 <= b.n) {
#pragma unroll
                    for (int j = 0; j < 6; ++j)
                        wmma::store_matrix_sync(out + j * 16, dxin[j], NB_MLP_INPUTS, wmma::mem_row_major);
                } else {
#pragma unroll
                    for (int j = 0; j < 6; ++j) {
                        wmma::store_matrix_sync(stage, dxin[j], kLdS, wmma::mem_row_major);
                        __syncwarp();
                        for (int e = lane; e < 256; e += 32) {
                            const int r = e / 16, c = e % 16;
                            if (s0 + r < b.n) out[size_t(r) * NB_MLP_INPUTS + j * 16 + c] = stage[r * kLdS + c];
                        }
                        __syncwarp();
                    }
                }
            }
            __syncthreads(); // all dZ_m rows written
            if (m == 3) weight_grad<2>(sH[3], kLdH, sH[2], kLdH, tr, tc0_h, g3);
            else if (m == 2) weight_grad<2>(sH[2], kLdH, sH[1], kLdH, tr, tc0_h, g2);
            else if (m == 1) weight_grad<2>(sH[1], kLdH, sH[0], kLdH, tr, tc0_h, g1);
            else weight_grad<3>(sH[0], kLdH, sX0, kLdIn, tr, tc0_in, g0);
        }
        __syncthreads(); // before the next tile overwrites the buffers
    }
    // The block's slice of the MLP gradient (summed over blocks in block order by k_reduce_check,
    // update_kernels.cu; every value written).
    store_weight_grad<3>(slice + nb_mlp_layer_offset(0), NB_MLP_INPUTS, tr, tc0_in, g0);
    store_weight_grad<2>(slice + nb_mlp_layer_offset(1), NB_MLP_WIDTH, tr, tc0_h, g1);
    store_weight_grad<2>(slice + nb_mlp_layer_offset(2), NB_MLP_WIDTH, tr, tc0_h, g2);
    store_weight_grad<2>(slice + nb_mlp_layer_offset(3), NB_MLP_WIDTH, tr, tc0_h, g3);
    if (warp < 4) store_weight_grad<1>(slice + nb_mlp_layer_offset(4), NB_MLP_WIDTH, 0, warp, g4);
}

} // namespace

void launch_encode(const DevNetwork& net, const DevBatch& b, cudaStream_t s) {
    const uint32_t n = b.n * NB_SEGMENT_POINTS * NB_GRID_MAX_LEVELS;
    k_encode<<<(n + 255) / 256, 256, 0, s>>>(net, b);
    NBVH_CUDA_CHECK(cudaGetLastError());
}

CoarseSplit coarse_split(const DevNetwork& net, bool deterministic) {
    // The leading levels (offset 0..) whose values fit the shared-memory accumulator.
    CoarseSplit c;
    while (!deterministic && c.levels < NB_GRID_MAX_LEVELS &&
           (net.levels[c.levels].offset + net.levels[c.levels].size) * 4u * 4u <= kCoarseSmemBytes) {
        c.values = (net.levels[c.levels].offset + net.levels[c.levels].size) * 4u;
        c.levels++;
    }
    return c;
}

void launch_grid_backward(const DevNetwork& net, const DevBatch& b, bool deterministic, uint32_t* flag,
                          cudaStream_t s) {
    const CoarseSplit split = coarse_split(net, deterministic);
    const uint32_t coarse = split.levels, values = split.values;
    if (coarse > 0) {
        static bool attr = false;
        if (!attr) {
            NBVH_CUDA_CHECK(cudaFuncSetAttribute(k_grid_backward_coarse, cudaFuncAttributeMaxDynamicSharedMemorySize,
                                                 int(kCoarseSmemBytes)));
            attr = true;
        }
        int dev = 0, sms = 1;
        NBVH_CUDA_CHECK(cudaGetDevice(&dev));
        NBVH_CUDA_CHECK(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, dev));
        k_grid_backward_coarse<<<2 * sms, 512, values * 2, s>>>(net, b, coarse, values, flag);
        NBVH_CUDA_CHECK(cudaGetLastError());
    }
    if (coarse == NB_GRID_MAX_LEVELS) return;
    const uint32_t n = b.n * NB_SEGMENT_POINTS * (NB_GRID_MAX_LEVELS - coarse);
    k_grid_backward<<<(n + 255) / 256, 256, 0, s>>>(net, b, deterministic ? 1 : 0, coarse, flag);
    NBVH_CUDA_CHECK(cudaGetLastError());
}

void mlp_prepare() {
    NBVH_CUDA_CHECK(cudaFuncSetAttribute(k_mlp, cudaFuncAttributeMaxDynamicSharedMemorySize, int(kSmemTotal)));
}

int mlp_blocks_for(uint32_t n) {
    int dev = 0, sms = 1;
    NBVH_CUDA_CHECK(cudaGetDevice(&dev));
    NBVH_CUDA_CHECK(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, dev));
    const int tiles = int((n + kTile - 1) / kTile);
    return tiles < sms ? (tiles > 0 ? tiles : 1) : sms;
}

void launch_mlp(const DevNetwork& net, const DevBatch& b, const LossParams& lp, float* slices, int blocks,
                uint32_t* flag, cudaStream_t s) {
    k_mlp<<<blocks, kWarps * 32, kSmemTotal, s>>>(net, b, lp, slices, flag);
    NBVH_CUDA_CHECK(cudaGetLastError());
}

} // namespace nbvh::cuda
