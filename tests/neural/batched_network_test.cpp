// The batched (tiled) training path equals the per-sample reference up to float reassociation:
// outputs, MLP weight gradients and grid gradients within 1e-5 relative, for full and partial tiles,
// dense and sparse grid sinks.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "engine/neural/batched_network.h"
#include "engine/neural/reference_network.h"
#include "tests/neural/test_networks.h"

using namespace nbvh;
using namespace nbvh::neural;

namespace {

std::vector<SegmentQuery> queries(size_t n, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-0.05f, 1.05f);
    std::vector<SegmentQuery> qs(n);
    for (auto& q : qs) {
        const vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
        q.points = {a, a * 0.5f + b * 0.5f, b};
    }
    return qs;
}

Outputs loss_grad(size_t i) {
    Outputs g;
    for (uint32_t k = 0; k < NB_MLP_OUTPUTS; ++k) g[k] = float(int(i % 7) - 3) * 0.2f + 0.03f * float(k);
    return g;
}

void check_against_reference(const NetworkWeights& w, size_t n, uint32_t seed) {
    const auto qs = queries(n, seed);
    // Reference: per-sample forward/backward, grid gradients summed densely.
    Gradients ref;
    ref.reset();
    std::vector<float> ref_grid(w.grid.size(), 0.0f);
    std::vector<Outputs> ref_y(n);
    ForwardCache c;
    for (size_t i = 0; i < n; ++i) {
        ref_y[i] = forward(w, qs[i], Precision::fp32, &c);
        ref.grid.clear();
        backward(w, c, loss_grad(i), ref);
        for (const auto& e : ref.grid) ref_grid[e.index] += e.grad;
    }
    // Batched, both grid sinks.
    auto tile = make_batch_tile();
    std::vector<float> mlp(NB_MLP_WEIGHT_COUNT, 0.0f), mlp2(NB_MLP_WEIGHT_COUNT, 0.0f), dense(w.grid.size(), 0.0f);
    std::vector<GridGrad<float>> sparse;
    for (size_t b = 0; b < n; b += kBatchTile) {
        const size_t e = std::min(n, b + kBatchTile);
        const std::span<const SegmentQuery> span(qs.data() + b, e - b);
        forward_tile(w, span, *tile);
        ASSERT_EQ(tile->n, e - b);
        for (size_t i = b; i < e; ++i) {
            const Outputs y = tile->output(uint32_t(i - b));
            for (uint32_t k = 0; k < NB_MLP_OUTPUTS; ++k)
                ASSERT_NEAR(y[k], ref_y[i][k], 1e-5f * std::fabs(ref_y[i][k]) + 1e-7f) << i << " " << k;
            tile->set_dl_dy(uint32_t(i - b), loss_grad(i));
        }
        backward_tile(w, *tile, mlp.data(), GridGradSink{dense.data(), nullptr});
        forward_tile(w, span, *tile);
        for (size_t i = b; i < e; ++i) tile->set_dl_dy(uint32_t(i - b), loss_grad(i));
        backward_tile(w, *tile, mlp2.data(), GridGradSink{nullptr, &sparse});
    }
    EXPECT_EQ(sparse.size(), n * size_t(NB_MLP_INPUTS * NB_GRID_CORNERS));
    std::vector<float> from_sparse(w.grid.size(), 0.0f);
    for (const auto& e : sparse) from_sparse[e.index] += e.grad;

    float max_m = 0, max_g = 0;
    for (float v : ref.mlp) max_m = std::max(max_m, std::fabs(v));
    for (float v : ref_grid) max_g = std::max(max_g, std::fabs(v));
    ASSERT_GT(max_m, 0.0f);
    ASSERT_GT(max_g, 0.0f);
    size_t nonzero = 0;
    for (size_t i = 0; i < mlp.size(); ++i) {
        // Each weight gradient is a sum of n products: relative to its own magnitude plus a floor
        // of 1e-5 of the largest (cancellation in sums of mixed-sign terms).
        ASSERT_NEAR(mlp[i], ref.mlp[i], 1e-5f * (std::fabs(ref.mlp[i]) + max_m)) << "mlp " << i;
        ASSERT_EQ(mlp[i], mlp2[i]) << "mlp " << i; // deterministic
        nonzero += ref.mlp[i] != 0.0f;
    }
    EXPECT_GT(nonzero, NB_MLP_WEIGHT_COUNT / 2);
    for (size_t i = 0; i < dense.size(); ++i) {
        ASSERT_NEAR(dense[i], ref_grid[i], 1e-5f * (std::fabs(ref_grid[i]) + max_g)) << "grid " << i;
        ASSERT_EQ(dense[i], from_sparse[i]) << "grid " << i;
    }
}

} // namespace

TEST(BatchedNetwork, FullTilesMatchReference) { check_against_reference(test::large_value_network(11), 4 * kBatchTile, 11); }

TEST(BatchedNetwork, PartialTileMatchesReference) { check_against_reference(test::large_value_network(12), kBatchTile + 17, 12); }

TEST(BatchedNetwork, TcnnInitMatchesReference) {
    NeuralConfig cfg;
    cfg.log2_hash_size = 14;
    check_against_reference(create_network(cfg, 13), 2 * kBatchTile - 1, 13);
}

TEST(BatchedNetwork, EmptyTileIsANoOp) {
    const NetworkWeights w = test::large_value_network(14);
    auto tile = make_batch_tile();
    forward_tile(w, {}, *tile);
    std::vector<float> mlp(NB_MLP_WEIGHT_COUNT, 0.0f), dense(w.grid.size(), 0.0f);
    backward_tile(w, *tile, mlp.data(), GridGradSink{dense.data(), nullptr});
    for (float v : mlp) ASSERT_EQ(v, 0.0f);
    for (float v : dense) ASSERT_EQ(v, 0.0f);
}
