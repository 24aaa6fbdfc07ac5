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
#include "engine/render/neural_model_gpu.h"
#include "engine/vk/context.h"
#include "tests/neuralvk/neural_test_model.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <random>

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

// Random rays through random sub-boxes (leaves) of the asset box; a quarter start inside their leaf.
std::vector<GpuNeuralQuery> random_queries(uint64_t seed, size_t n, glm::vec3 lo, glm::vec3 hi) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<GpuNeuralQuery> out;
    while (out.size() < n) {
        glm::vec3 a = lo + (hi - lo) * glm::vec3(u(rng), u(rng), u(rng));
        glm::vec3 b = lo + (hi - lo) * glm::vec3(u(rng), u(rng), u(rng));
        glm::vec3 llo = glm::min(a, b), lhi = glm::max(a, b);
        glm::vec3 target = llo + (lhi - llo) * glm::vec3(u(rng), u(rng), u(rng));
        glm::vec3 dir = glm::normalize(glm::vec3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f) + 1e-6f);
        const bool inside = out.size() % 4 == 0;
        glm::vec3 org = inside ? target : target - dir * (0.5f + 3.0f * u(rng));
        GpuNeuralQuery q;
        q.origin = org;
        q.dir = dir;
        if (!nb_neural_leaf_interval(org, nb_safe_inv_dir(dir), llo, lhi, q.t_entry, q.t_exit)) continue;
        if (q.t_exit <= 0.0f) continue;
        out.push_back(q);
    }
    return out;
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
    const std::vector<GpuNeuralQuery> qs = random_queries(11, 3000, lo, hi);
    const std::vector<GpuNeuralHit> hits = eval.evaluate(qs);
    ASSERT_EQ(hits.size(), qs.size());

    float max_out = 0.0f, max_t = 0.0f, max_n = 0.0f;
    int decisions = 0, near_threshold = 0, visible = 0, reversed = 0;
    for (size_t i = 0; i < qs.size(); ++i) {
        const neural::Outputs y = test::reference_outputs(tm, qs[i]);
        const GpuNeuralHit& h = hits[i];
        ASSERT_TRUE(std::isfinite(h.visibility) && std::isfinite(h.depth) && std::isfinite(h.t)) << i;
        max_out = std::max({max_out, std::abs(h.visibility - y[NB_OUT_VISIBILITY]), std::abs(h.depth - y[NB_OUT_DEPTH])});
        for (int k = 0; k < 3; ++k) max_out = std::max(max_out, std::abs(h.albedo[k] - y[NB_OUT_ALBEDO + k]));
        // Decisions.
        const bool ref_vis = nb_decode_visibility(y[NB_OUT_VISIBILITY], NB_VISIBILITY_THRESHOLD);
        if (std::abs(y[NB_OUT_VISIBILITY] - NB_VISIBILITY_THRESHOLD) < VIS_MARGIN) {
            ++near_threshold;
        } else {
            ++decisions;
            EXPECT_EQ((h.flags & NB_NEURAL_VISIBLE) != 0, ref_vis) << "query " << i << " y0 " << y[0];
        }
        visible += ref_vis;
        float t_ref;
        const bool acc_ref = nb_decode_depth(tm.box, y[NB_OUT_DEPTH], qs[i].t_entry, qs[i].t_exit, t_ref);
        reversed += nb_query_reversed(qs[i].t_entry);
        const float len = std::max(qs[i].t_exit - qs[i].t_entry, 0.0f) + tm.box.depth_pad;
        const float t_err = std::abs(h.t - t_ref) / len;
        max_t = std::max(max_t, t_err);
        EXPECT_LE(t_err, OUT_TOL) << "query " << i;
        if (std::abs(t_ref - qs[i].t_exit + NB_DEPTH_EPSILON * (len - tm.box.depth_pad) + tm.box.fixed_depth_eps) >
            OUT_TOL * len)
            EXPECT_EQ((h.flags & NB_NEURAL_ACCEPTED) != 0, acc_ref) << "query " << i;
        const glm::vec3 nraw(2 * y[2] - 1, 2 * y[3] - 1, 2 * y[4] - 1);
        if (glm::length(nraw) > 0.05f) {
            const glm::vec3 n_ref = nb_decode_normal(y[2], y[3], y[4]);
            max_n = std::max(max_n, glm::length(h.normal - n_ref));
        }
    }
    std::printf("scalar vs fp16 reference over %zu queries (%d reversed): max |dy| %.3g, max |dt|/L %.3g, "
                "max |dn| %.3g; %d decisions (%d visible), %d near the threshold\n",
                qs.size(), reversed, max_out, max_t, max_n, decisions, visible, near_threshold);
    EXPECT_LE(max_out, OUT_TOL);
    EXPECT_LE(max_n, 0.01f);
    // The test must exercise both decisions and reversed queries.
    EXPECT_GT(visible, int(qs.size() / 10));
    EXPECT_LT(visible, int(qs.size() * 9 / 10));
    EXPECT_GT(reversed, int(qs.size() / 8));
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
