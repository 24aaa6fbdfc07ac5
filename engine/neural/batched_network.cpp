// Batched fp32 forward/backward of the N-BVH network (see batched_network.h).
#include "engine/neural/batched_network.h"

#include <algorithm>
#include <cstring>

#include "engine/core/error.h"

// Two code paths of the MLP kernels chosen at load time (ifunc): x86-64-v3 (AVX2 + FMA) and the
// build's baseline. Portable: other compilers/targets get the baseline only.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && !defined(NBVH_NO_TARGET_CLONES)
#define NBVH_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define NBVH_CLONES
#endif
#if defined(__GNUC__)
#define NBVH_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define NBVH_ALWAYS_INLINE inline
#endif

#ifndef NBVH_PREFETCH_GROUP
#define NBVH_PREFETCH_GROUP 4
#endif

namespace nbvh::neural {
namespace {

constexpr uint32_t B = kBatchTile;
constexpr uint32_t kW = NB_MLP_WIDTH;
constexpr uint32_t kIn = NB_MLP_INPUTS;
constexpr uint32_t kOut = NB_MLP_OUTPUTS;
// Samples whose grid lines are prefetched together, one group ahead (4 x 192 lookups; the coarse
// levels' lines repeat, so a few hundred distinct lines are in flight at most).
constexpr uint32_t kGroup = NBVH_PREFETCH_GROUP;

inline void prefetch_read(const float* p) {
#if defined(__GNUC__)
    __builtin_prefetch(p, 0, 3);
#else
    (void)p;
#endif
}
inline void prefetch_write(float* p) {
#if defined(__GNUC__)
    __builtin_prefetch(p, 1, 3);
#else
    (void)p;
#endif
}

// Y[r][b] = (relu?)(sum_c W[r][c] X[c][b]) for r < R: per (r, b) the sum runs over c in ascending
// order, exactly as the reference's matvec; the inner loop is over the batch.
template <uint32_t R, uint32_t C, bool kRelu>
NBVH_ALWAYS_INLINE void layer_forward(const float* __restrict W, const float* __restrict X, float* __restrict Y) {
    for (uint32_t r = 0; r < R; ++r) {
        alignas(64) float acc[B] = {};
        const float* __restrict wr = W + r * C;
        for (uint32_t c = 0; c < C; ++c) {
            const float wv = wr[c];
            const float* __restrict xc = X + c * B;
            for (uint32_t b = 0; b < B; ++b) acc[b] += wv * xc[b];
        }
        float* __restrict yr = Y + r * B;
        for (uint32_t b = 0; b < B; ++b) yr[b] = kRelu ? std::max(acc[b], 0.0f) : acc[b];
    }
}

// out[b][c] = in[c][b] for a [C][B] matrix.
template <uint32_t C>
NBVH_ALWAYS_INLINE void transpose_to_samples(const float* __restrict in, float* __restrict out) {
    for (uint32_t c = 0; c < C; ++c)
        for (uint32_t b = 0; b < B; ++b) out[b * C + c] = in[c * B + b];
}

// 8 floats as one value (GCC vector extension: AVX register in the x86-64-v3 clone, two SSE
// registers in the baseline); unaligned loads/stores through memcpy. The helpers are always inlined
// into the kernels, so the -Wpsabi note (AVX vector return in a non-AVX function) does not apply.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
typedef float V8 __attribute__((vector_size(32)));
NBVH_ALWAYS_INLINE V8 load8(const float* p) {
    V8 v;
    std::memcpy(&v, p, sizeof(v));
    return v;
}
NBVH_ALWAYS_INLINE void store8(float* p, const V8& v) { std::memcpy(p, &v, sizeof(v)); }

// One matrix backward. dz: [R][B] dL/d(pre-activation). Adds dL/dW = sum_b dz[r][b] X[c][b] to G
// (tile partial sums over the samples in order) and writes
// dx[c][b] = sum_r W[r][c] dz[r][b] (rows in ascending order, as the reference), masked by the ReLU
// of X when X is a hidden activation (derivative 0 at 0, as tcnn).
template <uint32_t R, uint32_t C, bool kMaskRelu>
NBVH_ALWAYS_INLINE void layer_backward(const float* __restrict W, const float* __restrict X, const float* __restrict dz,
                              float* __restrict xt, float* __restrict dzt, float* __restrict G,
                              float* __restrict dx) {
    transpose_to_samples<C>(X, xt);
    transpose_to_samples<R>(dz, dzt);
    // Register blocks of 4 rows x 16 columns (8 vectors of 8 floats: 2 AVX registers or 4 SSE
    // registers each), summed over the tile's samples in order, then added to G.
    for (uint32_t r0 = 0; r0 < R; r0 += 4) {
        for (uint32_t c0 = 0; c0 < C; c0 += 16) {
            V8 acc[4][2] = {};
            for (uint32_t b = 0; b < B; ++b) {
                const V8 x0 = load8(xt + b * C + c0), x1 = load8(xt + b * C + c0 + 8);
                for (uint32_t k = 0; k < 4; ++k) {
                    const float d = dzt[b * R + r0 + k];
                    acc[k][0] += d * x0;
                    acc[k][1] += d * x1;
                }
            }
            for (uint32_t k = 0; k < 4; ++k) {
                float* __restrict gk = G + (r0 + k) * C + c0;
                store8(gk, load8(gk) + acc[k][0]);
                store8(gk + 8, load8(gk + 8) + acc[k][1]);
            }
        }
    }
    for (uint32_t c = 0; c < C; ++c) {
        alignas(64) float acc[B] = {};
        for (uint32_t r = 0; r < R; ++r) {
            const float wv = W[r * C + c];
            const float* __restrict dr = dz + r * B;
            for (uint32_t b = 0; b < B; ++b) acc[b] += wv * dr[b];
        }
        const float* __restrict xc = X + c * B;
        float* __restrict out = dx + c * B;
        for (uint32_t b = 0; b < B; ++b) out[b] = kMaskRelu ? (xc[b] > 0.0f ? acc[b] : 0.0f) : acc[b];
    }
}

NBVH_CLONES void mlp_forward_kernel(const float* __restrict mlp, BatchTile& t) {
    layer_forward<kW, kIn, true>(mlp + nb_mlp_layer_offset(0), t.x0, t.h[0]);
    layer_forward<kW, kW, true>(mlp + nb_mlp_layer_offset(1), t.h[0], t.h[1]);
    layer_forward<kW, kW, true>(mlp + nb_mlp_layer_offset(2), t.h[1], t.h[2]);
    layer_forward<kW, kW, true>(mlp + nb_mlp_layer_offset(3), t.h[2], t.h[3]);
    // R4: fp32 pre-activation of the 8 real outputs (padding rows 8..15 never read), then the sigmoid.
    layer_forward<kOut, kW, false>(mlp + nb_mlp_layer_offset(4), t.h[3], t.y);
    for (uint32_t i = 0; i < kOut * B; ++i) t.y[i] = nb_sigmoid(t.y[i]);
}

NBVH_CLONES void mlp_backward_kernel(const float* __restrict mlp, BatchTile& t, float* __restrict g) {
    // Output layer: dz = dL/dy * y (1 - y); padding rows get no gradient.
    for (uint32_t i = 0; i < kOut * B; ++i) t.dz[i] = t.dy[i] * t.y[i] * (1.0f - t.y[i]);
    layer_backward<kOut, kW, true>(mlp + nb_mlp_layer_offset(4), t.h[3], t.dz, t.xt, t.dzt,
                                   g + nb_mlp_layer_offset(4), t.dx);
    for (uint32_t m = NB_MLP_HIDDEN_LAYERS - 1; m >= 1; --m) {
        std::memcpy(t.dz, t.dx, sizeof(float) * kW * B);
        layer_backward<kW, kW, true>(mlp + nb_mlp_layer_offset(m), t.h[m - 1], t.dz, t.xt, t.dzt,
                                     g + nb_mlp_layer_offset(m), t.dx);
    }
    std::memcpy(t.dz, t.dx, sizeof(float) * kW * B);
    layer_backward<kW, kIn, false>(mlp + nb_mlp_layer_offset(0), t.x0, t.dz, t.xt, t.dzt, g, t.dx);
}

} // namespace

Outputs BatchTile::output(uint32_t i) const {
    Outputs o;
    for (uint32_t r = 0; r < kOut; ++r) o[r] = y[r * B + i];
    return o;
}

void BatchTile::set_dl_dy(uint32_t i, const Outputs& g) {
    for (uint32_t r = 0; r < kOut; ++r) dy[r * B + i] = g[r];
}

std::unique_ptr<BatchTile> make_batch_tile() { return std::make_unique<BatchTile>(); }

void forward_tile(const NetworkWeights& w, std::span<const SegmentQuery> queries, BatchTile& t) {
    NBVH_CHECK(queries.size() <= B && w.levels.size() == NB_GRID_MAX_LEVELS && w.mlp.size() == NB_MLP_WEIGHT_COUNT);
    t.n = uint32_t(queries.size());
    std::fill(std::begin(t.x0), std::end(t.x0), 0.0f); // padding samples: zero features
    std::fill(std::begin(t.dy), std::end(t.dy), 0.0f);
    const float* grid = w.grid.data();
    // Hash-grid encode: the reference's encode_point in two passes over groups of kGroup samples, so
    // the grid reads (random, mostly cache misses) do not wait for index arithmetic: the corner value
    // indices and weights of group g+1 are computed (and their lines prefetched) before the trilinear
    // sums of group g (reference corner order). Indices/weights stay for the backward scatter.
    auto lookups = [&](uint32_t g0) {
        for (uint32_t i = g0; i < std::min(t.n, g0 + kGroup); ++i) {
            uint32_t* cv = t.corner_value + size_t(i) * BatchTile::kLookups;
            float* cw = t.corner_weight + size_t(i) * BatchTile::kLookups;
            for (uint32_t k = 0; k < NB_SEGMENT_POINTS; ++k)
                for (uint32_t l = 0; l < NB_GRID_MAX_LEVELS; ++l) {
                    const GpuHashLevel& lv = w.levels[l];
                    uvec3 cell;
                    vec3 frac;
                    nb_grid_position(lv, queries[i].points[k], cell, frac);
                    for (uint32_t c = 0; c < NB_GRID_CORNERS; ++c) {
                        *cw++ = nb_grid_corner_weight(frac, c);
                        *cv = nb_grid_corner_entry(lv, cell, c) * NB_GRID_FEATURES;
                        prefetch_read(grid + *cv++);
                    }
                }
        }
    };
    if (t.n > 0) lookups(0);
    for (uint32_t g0 = 0; g0 < t.n; g0 += kGroup) {
        if (g0 + kGroup < t.n) lookups(g0 + kGroup);
        for (uint32_t i = g0; i < std::min(t.n, g0 + kGroup); ++i) {
            const uint32_t* cv = t.corner_value + size_t(i) * BatchTile::kLookups;
            const float* cw = t.corner_weight + size_t(i) * BatchTile::kLookups;
            // kl = k * levels + l, so nb_feature_slot(k, l, f) = kl * NB_GRID_FEATURES + f.
            for (uint32_t kl = 0; kl < NB_SEGMENT_POINTS * NB_GRID_MAX_LEVELS; ++kl) {
                float acc[NB_GRID_FEATURES] = {};
                for (uint32_t c = 0; c < NB_GRID_CORNERS; ++c, ++cv, ++cw)
                    for (uint32_t f = 0; f < NB_GRID_FEATURES; ++f) acc[f] += *cw * grid[*cv + f];
                for (uint32_t f = 0; f < NB_GRID_FEATURES; ++f) t.x0[(kl * NB_GRID_FEATURES + f) * B + i] = acc[f];
            }
        }
    }
    mlp_forward_kernel(w.mlp.data(), t);
}

void backward_tile(const NetworkWeights& w, BatchTile& t, float* mlp_grad, GridGradSink sink) {
    NBVH_CHECK((sink.dense != nullptr) != (sink.sparse != nullptr));
    mlp_backward_kernel(w.mlp.data(), t, mlp_grad);
    // Grid: scatter dL/dfeature to the 8 corners of every level of every point (reference order),
    // prefetching the destination lines of the next group of samples (dense sink: random writes).
    auto prefetch_group = [&](uint32_t g0) {
        const uint32_t g1 = std::min(t.n, g0 + kGroup);
        for (uint32_t j = g0 * BatchTile::kLookups; j < g1 * BatchTile::kLookups; ++j)
            prefetch_write(sink.dense + t.corner_value[j]);
    };
    if (sink.dense && t.n > 0) prefetch_group(0);
    for (uint32_t g0 = 0; g0 < t.n; g0 += kGroup) {
        const uint32_t g1 = std::min(t.n, g0 + kGroup);
        if (sink.dense && g1 < t.n) prefetch_group(g1);
        for (uint32_t i = g0; i < g1; ++i) {
            const uint32_t* cv = t.corner_value + size_t(i) * BatchTile::kLookups;
            const float* cw = t.corner_weight + size_t(i) * BatchTile::kLookups;
            for (uint32_t kl = 0; kl < NB_SEGMENT_POINTS * NB_GRID_MAX_LEVELS; ++kl) {
                float df[NB_GRID_FEATURES];
                for (uint32_t f = 0; f < NB_GRID_FEATURES; ++f) df[f] = t.dx[(kl * NB_GRID_FEATURES + f) * B + i];
                for (uint32_t c = 0; c < NB_GRID_CORNERS; ++c, ++cv, ++cw) {
                    if (sink.dense) {
                        float* dst = sink.dense + *cv;
                        for (uint32_t f = 0; f < NB_GRID_FEATURES; ++f) dst[f] += *cw * df[f];
                    } else {
                        for (uint32_t f = 0; f < NB_GRID_FEATURES; ++f)
                            sink.sparse->push_back({*cv + f, *cw * df[f]});
                    }
                }
            }
        }
    }
}

} // namespace nbvh::neural
