// Batched fp32 forward/backward of the N-BVH network for CPU training: the same math as the per-sample
// reference (reference_network.h), on tiles of kBatchTile queries at a time so that the MLP becomes
// small matrix-matrix products (W[64x96] . X[96xB]) whose inner loops run contiguously over the batch
// and auto-vectorise (-O3, no intrinsics). The hot MLP kernels are compiled twice (x86-64-v3 and
// baseline) and picked at load time where the compiler supports target_clones.
//
// Numerics: the hash-grid encode and the grid scatter use the shared header's index/weight functions
// (shaders/shared/hashgrid.h) in the reference's order; the forward dot products sum over the inputs
// in the reference's column order, dL/dx sums over the rows in the reference's order. The weight
// gradient of a tile is summed over the tile's samples first and then added to the caller's buffer
// (the reference adds sample by sample), and the x86-64-v3 clone may fuse multiply-adds: results
// differ from the reference by float reassociation/rounding only (tests/neural/batched_network_test).
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "engine/neural/reference_network.h"

namespace nbvh::neural {

// Samples per tile. Shorter tiles are padded with zero inputs whose dL/dy is zero (no effect).
constexpr uint32_t kBatchTile = 64;

// Where the grid gradient goes: a dense buffer (one float per grid value, +=), or, for tables too big
// to hold one dense copy per thread, appended (index, grad) pairs (indices repeat; sum them).
struct GridGradSink {
    float* dense = nullptr;
    std::vector<GridGrad<float>>* sparse = nullptr;
};

// Working memory of one tile (about 250 KiB; allocate once per thread and reuse). Layouts are
// feature-major ([feature][sample], sample contiguous) so the batch is the vectorised dimension.
struct BatchTile {
    static constexpr uint32_t B = kBatchTile;
    static constexpr uint32_t kLookups = NB_SEGMENT_POINTS * NB_GRID_MAX_LEVELS * NB_GRID_CORNERS; // 192
    uint32_t n = 0; // valid samples (0..B)
    alignas(64) float x0[NB_MLP_INPUTS * B];                        // features
    alignas(64) float h[NB_MLP_HIDDEN_LAYERS][NB_MLP_WIDTH * B];    // hidden activations after ReLU
    alignas(64) float y[NB_MLP_OUTPUTS * B];                        // outputs after the sigmoid
    alignas(64) float dy[NB_MLP_OUTPUTS * B];                       // dL/dy (post-sigmoid), set by the caller
    alignas(64) uint32_t corner_value[kLookups * B];                // [sample][lookup] value index entry*4
    alignas(64) float corner_weight[kLookups * B];                  // [sample][lookup] trilinear weight
    // Backward scratch.
    alignas(64) float dz[NB_MLP_WIDTH * B];     // dL/d(pre-activation) of the current layer
    alignas(64) float dx[NB_MLP_INPUTS * B];    // dL/d(layer input)
    alignas(64) float xt[B * NB_MLP_INPUTS];    // layer input transposed ([sample][feature])
    alignas(64) float dzt[B * NB_MLP_WIDTH];    // dz transposed ([sample][row])

    Outputs output(uint32_t i) const;
    void set_dl_dy(uint32_t i, const Outputs& g);
};

std::unique_ptr<BatchTile> make_batch_tile();

// fp32 forward of queries (size <= kBatchTile) into `t` (t.n = size; dL/dy of every slot reset to 0).
void forward_tile(const NetworkWeights& w, std::span<const SegmentQuery> queries, BatchTile& t);

// Backward of the tile's last forward with t.dy: mlp_grad (NB_MLP_WEIGHT_COUNT) += dL/dW summed over
// the tile; grid gradients into `grid` (sample by sample, per sample in the reference's order).
void backward_tile(const NetworkWeights& w, BatchTile& t, float* mlp_grad, GridGradSink grid);

} // namespace nbvh::neural
