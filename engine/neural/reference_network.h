// CPU reference of the N-BVH network (hash grid + MLP, paper §4): forward in fp32 (or double, for
// gradient checks) and with the scalar GLSL path's fp16 rounding emulated (rounding points R1-R4 in
// shaders/shared/mlp.h), and backward to the MLP weights and grid features. All index arithmetic
// comes from shaders/shared/ (hashgrid.h, mlp.h): this file holds no second copy of the layout.
//
// Gradients are taken w.r.t. the network's OUTPUTS AFTER THE SIGMOID (dL/dy, as tcnn losses produce
// them); backward applies the sigmoid derivative y(1-y) itself. Backward uses the values cached by the
// forward pass it follows (so fp16-emulated forward -> gradients of that emulated network, with the
// master (unrounded) weights in the transposed products).
#pragma once
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "engine/neural/level_table.h"
#include "engine/neural/neural_config.h"
#include "shaders/shared/hashgrid.h"
#include "shaders/shared/mlp.h"

namespace nbvh::neural {

enum class Precision { fp32, fp16_emulated };

// Parameters of one network. T = float for everything real (fp32 master copy); T = double only in
// tests. grid: level_table_entries(levels) * NB_GRID_FEATURES values, value (entry e, feature f) at
// e*4 + f. mlp: NB_MLP_WEIGHT_COUNT weights in the order of mlp.h (tcnn order).
template <class T>
struct NetworkWeightsT {
    NeuralConfig cfg;
    std::vector<GpuHashLevel> levels;
    std::vector<T> grid;
    std::vector<T> mlp;
};
using NetworkWeights = NetworkWeightsT<float>;

// tcnn initialisation: grid uniform in [-1e-4, 1e-4]; MLP Xavier-uniform +-sqrt(6/(fan_in+fan_out))
// with the padded output width (16) as fan_out of the last matrix; padding rows 8..15 of the last
// matrix are then zeroed (they never influence outputs). Deterministic for a seed (std::mt19937_64;
// tcnn's pcg32 stream is not reproduced). Throws nbvh::Error on unsupported hyperparameters.
NetworkWeights create_network(const NeuralConfig& cfg, uint64_t seed);
// Checks sizes (levels vs cfg, grid and mlp lengths) and that every parameter is finite.
void validate_network(const NetworkWeights& w);
// fp16 export (round to nearest even), for the model file and the GPU.
std::vector<uint16_t> mlp_to_fp16(const NetworkWeights& w);
std::vector<uint16_t> grid_to_fp16(const NetworkWeights& w);
NetworkWeightsT<double> to_double(const NetworkWeights& w);

// One query: the 3 encoded points (neural_query.h nb_segment_points), in query order.
struct SegmentQuery {
    std::array<vec3, NB_SEGMENT_POINTS> points;
};

template <class T>
using OutputsT = std::array<T, NB_MLP_OUTPUTS>; // after the sigmoid, slots NB_OUT_*
using Outputs = OutputsT<float>;

// What backward needs from forward.
template <class T>
struct ForwardCacheT {
    SegmentQuery query;
    std::array<T, NB_MLP_INPUTS> features;                               // MLP input
    std::array<std::array<T, NB_MLP_WIDTH>, NB_MLP_HIDDEN_LAYERS> hidden; // after ReLU
    OutputsT<T> outputs;
};
using ForwardCache = ForwardCacheT<float>;

// Interpolated grid features of one point (32 values, level-major), fp32 or rounded as R1.
template <class T>
void encode_point(const NetworkWeightsT<T>& w, vec3 p, Precision prec, T* out32);

template <class T>
OutputsT<T> forward(const NetworkWeightsT<T>& w, const SegmentQuery& q, Precision prec,
                    ForwardCacheT<T>* cache = nullptr);

// A sparse grid gradient: value index (entry*4 + f) and dL/dvalue. Indices may repeat (sum them).
template <class T>
struct GridGrad {
    uint32_t index;
    T grad;
};

template <class T>
struct GradientsT {
    std::vector<T> mlp;               // NB_MLP_WEIGHT_COUNT, accumulated (+=)
    std::vector<GridGrad<T>> grid;    // appended
    void reset() {
        mlp.assign(NB_MLP_WEIGHT_COUNT, T(0));
        grid.clear();
    }
};
using Gradients = GradientsT<float>;

// Accumulates dL/dW (dense, +=) and dL/dgrid (appends 3 points x 8 levels x 8 corners x 4 entries)
// for one query, given dL/dy (post-sigmoid, slots 0..7). Optionally returns dL/dfeatures (96).
template <class T>
void backward(const NetworkWeightsT<T>& w, const ForwardCacheT<T>& cache, const OutputsT<T>& dl_dy,
              GradientsT<T>& grads, std::array<T, NB_MLP_INPUTS>* dl_dfeatures = nullptr);

// Batched versions over std::thread (threads = 0: hardware concurrency, capped by the batch).
void forward_batch(const NetworkWeights& w, std::span<const SegmentQuery> queries, Precision prec,
                   std::span<Outputs> out, unsigned threads = 0);
// Dense gradients of sum_i L_i: mlp_grad (NB_MLP_WEIGHT_COUNT) and grid_grad (w.grid.size()) are
// overwritten. dl_dy[i] is dL_i/dy_i. fp32 forward is recomputed inside.
void backward_batch(const NetworkWeights& w, std::span<const SegmentQuery> queries,
                    std::span<const Outputs> dl_dy, std::vector<float>& mlp_grad,
                    std::vector<float>& grid_grad, unsigned threads = 0);

} // namespace nbvh::neural
