// The scalar neural query kernel (passes/neural_eval_scalar.comp) on lavapipe against the CPU reference
// network with the shader's fp16 rounding emulated (engine/neural/reference_network.h,
// Precision::fp16_emulated), on random rays through random leaves of a random network.
//
// Bounds (why): the GPU and the CPU round at the same points (R1-R4 of shaders/shared/mlp.h); they may
// differ only where the driver fuses a*b+c or reorders nothing else, i.e. by fp32 roundings of a dot
// product (~1e-7 relative). Such a difference flips an fp16 rounding of an activation in rare cases
// (one half-ulp, 2^-11 relative), which the remaining layers can amplify by at most the product of the
// weight-row norms; with weights of this size that stays well below 1e-3 after the sigmoid (whose slope
// is <= 1/4). So: outputs within 2e-3, visibility decisions equal except where the reference is within
// 2e-3 of the threshold, depth decodes within 2e-3 * (L + pad), normals within 0.01 (their decode
// divides by |2y - 1|, so rows whose reference |2y - 1| is < 0.05 are skipped).
#include "engine/render/gpu_memory.h"
#include "engine/render/neural_model_gpu.h"
#include "engine/vk/context.h"
#include "shaders/shared/neural_occupancy.h"
#include "tests/neuralvk/neural_test_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

using namespace nbvh;
using namespace nbvh::render;

namespace {

constexpr float OUT_TOL = 2e-3f;
constexpr float VIS_MARGIN = 2e-3f;

vk::Context make_lavapipe() {
    vk::ContextOptions o;
    o.device = vk::DeviceChoice::cpu;
    o.validation = true;
    return vk::Context(o);
}

} // namespace

TEST(NeuralPath, LavapipeUsesScalarAndRefusesCoopmat) {
    vk::Context ctx = make_lavapipe();
    const NeuralKernelChoice c = choose_neural_kernel(ctx.features(), NeuralPath::automatic);
    EXPECT_EQ(c.path, NeuralPath::scalar);
    EXPECT_FALSE(coopmat_unavailable_reason(ctx.features()).empty());
    EXPECT_THROW(choose_neural_kernel(ctx.features(), NeuralPath::coopmat), Error);
    EXPECT_EQ(parse_neural_path("auto"), NeuralPath::automatic);
    EXPECT_THROW(parse_neural_path("tensor"), Error);
    EXPECT_EQ(ctx.validation_message_count(), 0);
}

TEST(NeuralPath, PackHalvesLowHalfIsEvenElement) {
    const std::vector<uint32_t> w = pack_halves({0x1111, 0x2222, 0x3333});
    ASSERT_EQ(w.size(), 2u);
    EXPECT_EQ(w[0], 0x22221111u);
    EXPECT_EQ(w[1], 0x00003333u);
}

TEST(NeuralCrossCheck, ScalarKernelMatchesFp16Reference) {
    vk::Context ctx = make_lavapipe();
    const glm::vec3 lo(-0.3f, 0.1f, -2.0f), hi(0.9f, 0.7f, 1.5f);
    const test::TestModel tm = test::make_test_model(7, lo, hi);
    NeuralModelGpu gpu(ctx, tm.model);
    NeuralEvaluator eval(ctx, gpu, choose_neural_kernel(ctx.features(), NeuralPath::scalar));
    const std::vector<GpuNeuralQuery> qs = test::random_queries(11, 3000, lo, hi);
    const std::vector<GpuNeuralHit> hits = eval.evaluate(qs);
    ASSERT_EQ(hits.size(), qs.size());
    const test::CrossCheck c = test::cross_check(tm, qs, hits, VIS_MARGIN);
    std::printf("scalar vs fp16 reference over %zu queries (%d reversed): max |dy| %.3g, max |dt|/L %.3g, "
                "max |dn| %.3g; %d decisions (%d visible), %d near the threshold\n",
                qs.size(), c.reversed, c.max_out, c.max_t, c.max_n, c.decisions, c.visible, c.near_threshold);
    EXPECT_EQ(c.non_finite, 0);
    EXPECT_LE(c.max_out, OUT_TOL);
    EXPECT_LE(c.max_t, OUT_TOL);
    EXPECT_LE(c.max_n, 0.01f);
    EXPECT_EQ(c.decision_errors, 0);
    EXPECT_EQ(c.acceptance_errors, 0);
    // The test must exercise both decisions and reversed queries.
    EXPECT_GT(c.visible, int(qs.size() / 10));
    EXPECT_LT(c.visible, int(qs.size() * 9 / 10));
    EXPECT_GT(c.reversed, int(qs.size() / 8));
    EXPECT_EQ(ctx.validation_message_count(), 0);
}

TEST(NeuralPath, TransposedWeightsForCooperativeMatrices) {
    std::vector<uint16_t> w(NB_MLP_WEIGHT_COUNT);
    for (size_t i = 0; i < w.size(); ++i) w[i] = uint16_t(i * 2654435761u >> 16);
    const std::vector<uint16_t> t = transpose_mlp(w);
    for (uint32_t m = 0; m < NB_MLP_MATRICES; ++m)
        for (uint32_t r : {0u, 5u, nb_mlp_layer_outputs(m) - 1u})
            for (uint32_t c : {0u, 17u, nb_mlp_layer_inputs(m) - 1u})
                EXPECT_EQ(t[nb_mlp_layer_offset(m) + nb_coop_weight_slot(nb_mlp_layer_outputs(m), c, r)],
                          w[nb_mlp_weight_index(m, r, c)]);
    // The tiling is a permutation of each matrix: every slot written exactly once.
    std::vector<int> hits(w.size(), 0);
    for (uint32_t m = 0; m < NB_MLP_MATRICES; ++m)
        for (uint32_t r = 0; r < nb_mlp_layer_outputs(m); ++r)
            for (uint32_t c = 0; c < nb_mlp_layer_inputs(m); ++c)
                ++hits[nb_mlp_layer_offset(m) + nb_coop_weight_slot(nb_mlp_layer_outputs(m), c, r)];
    EXPECT_EQ(std::count(hits.begin(), hits.end(), 1), std::ptrdiff_t(hits.size()));
}

// The host-side memory figure (engine/render/gpu_memory.h, what nbvh bench/study report) is what the
// model's buffers occupy on the device.
TEST(NeuralMemory, HostFigureMatchesTheUploadedBuffers) {
    vk::Context ctx = make_lavapipe();
    const test::TestModel tm = test::make_test_model(3, glm::vec3(-1.0f), glm::vec3(1.0f), 12);
    const NeuralModelGpu gpu(ctx, tm.model);
    const NeuralGpuBytes b = neural_gpu_bytes(tm.model);
    EXPECT_EQ(gpu.bytes(), b.total() - b.assets - b.params);
    EXPECT_EQ(b.occupancy, 0u);
    // With occupancy masks (after the bounds in the same buffer): counted on both sides.
    NeuralModel with_masks = tm.model;
    with_masks.occupancy.assign(with_masks.nodes.size() * NB_OCC_WORDS, ~0u);
    const NeuralModelGpu gpu_masks(ctx, with_masks);
    const NeuralGpuBytes bm = neural_gpu_bytes(with_masks);
    EXPECT_EQ(bm.occupancy, with_masks.nodes.size() * NB_OCC_WORDS * 4);
    EXPECT_EQ(gpu_masks.bytes(), bm.total() - bm.assets - bm.params);
    EXPECT_EQ(gpu_masks.bytes() - gpu.bytes(), bm.occupancy);
    EXPECT_GT(gpu_masks.occupancy_offset(), 0u);
    EXPECT_EQ(gpu.occupancy_offset(), 0u);
    EXPECT_EQ(ctx.validation_message_count(), 0);
}
