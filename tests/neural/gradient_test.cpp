// Gradient checks of the CPU reference (every MLP layer, the grid, the losses) against central finite
// differences in double precision, fp16 emulation vs fp32, batched vs single-sample.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/neural/fp16.h"
#include "engine/neural/losses.h"
#include "engine/neural/reference_network.h"
#include "tests/neural/test_networks.h"

using namespace nbvh;
using namespace nbvh::neural;

namespace {

std::vector<SegmentQuery> test_queries(int n, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<SegmentQuery> qs(n);
    for (auto& q : qs) {
        const vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
        q.points = {a, a * 0.5f + b * 0.5f, b};
    }
    return qs;
}

// L(params) = sum_k c_k y_k, so dL/dy = c.
double linear_loss(const NetworkWeightsT<double>& w, const SegmentQuery& q, const OutputsT<double>& c) {
    const auto y = forward(w, q, Precision::fp32);
    double l = 0;
    for (uint32_t k = 0; k < NB_MLP_OUTPUTS; ++k) l += c[k] * y[k];
    return l;
}

// Relative error bound of analytic double gradients against double central differences (step 1e-6):
// truncation ~h^2 and cancellation ~1e-16/h keep the error below 1e-6 relative; 1e-5 leaves margin.
constexpr double kRelTol = 1e-5;
constexpr double kAbsTol = 1e-10;

struct GradProbe {
    NetworkWeightsT<double> w;
    SegmentQuery q;
    OutputsT<double> c;
    GradientsT<double> g;
};

GradProbe make_setup(uint64_t seed) {
    GradProbe s{to_double(test::large_value_network(seed)), test_queries(1, uint32_t(seed))[0], {}, {}};
    std::mt19937 rng(uint32_t(seed) * 3u + 1u);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (double& v : s.c) v = u(rng);
    ForwardCacheT<double> cache;
    forward(s.w, s.q, Precision::fp32, &cache);
    s.g.reset();
    backward(s.w, cache, s.c, s.g);
    return s;
}

void expect_close(double analytic, double fd, const std::string& what) {
    EXPECT_LE(std::fabs(analytic - fd), kRelTol * std::max(std::fabs(analytic), std::fabs(fd)) + kAbsTol)
        << what << ": analytic " << analytic << " vs finite difference " << fd;
}

} // namespace

TEST(Gradients, EveryMlpLayerMatchesFiniteDifferences) {
    for (uint64_t seed : {1u, 2u}) {
        GradProbe s = make_setup(seed);
        std::mt19937 rng{uint32_t(seed)};
        for (uint32_t m = 0; m < NB_MLP_MATRICES; ++m) {
            const uint32_t rows = m == NB_MLP_HIDDEN_LAYERS ? NB_MLP_OUTPUTS : NB_MLP_WIDTH;
            // mostly weights with a nonzero gradient (rows of live ReLUs), plus a few arbitrary ones
            std::vector<uint32_t> live, picks;
            for (uint32_t r = 0; r < rows; ++r)
                for (uint32_t col = 0; col < nb_mlp_layer_inputs(m); ++col)
                    if (s.g.mlp[nb_mlp_weight_index(m, r, col)] != 0.0) live.push_back(nb_mlp_weight_index(m, r, col));
            ASSERT_GT(live.size(), 100u) << "layer " << m << ": too few live weights, the check would be vacuous";
            for (int k = 0; k < 20; ++k) picks.push_back(live[rng() % live.size()]);
            for (int k = 0; k < 4; ++k) picks.push_back(nb_mlp_weight_index(m, rng() % rows, rng() % nb_mlp_layer_inputs(m)));
            int nonzero = 0;
            for (uint32_t i : picks) {
                const double h = 1e-6, w0 = s.w.mlp[i];
                s.w.mlp[i] = w0 + h;
                const double lp = linear_loss(s.w, s.q, s.c);
                s.w.mlp[i] = w0 - h;
                const double lm = linear_loss(s.w, s.q, s.c);
                s.w.mlp[i] = w0;
                expect_close(s.g.mlp[i], (lp - lm) / (2 * h), strfmt("W%u weight %zu", unsigned(m), size_t(i)));
                nonzero += s.g.mlp[i] != 0.0;
            }
            EXPECT_GE(nonzero, 20) << "layer " << m << " gradients are mostly zero: the check would be vacuous";
        }
        // padding rows 8..15 of the output matrix never get a gradient
        for (uint32_t r = NB_MLP_OUTPUTS; r < NB_MLP_OUTPUTS_PADDED; ++r)
            for (uint32_t col = 0; col < NB_MLP_WIDTH; ++col)
                ASSERT_EQ(s.g.mlp[nb_mlp_weight_index(NB_MLP_HIDDEN_LAYERS, r, col)], 0.0);
    }
}

TEST(Gradients, GridFeaturesMatchFiniteDifferences) {
    GradProbe s = make_setup(3);
    std::map<uint32_t, double> grid;
    for (const auto& gg : s.g.grid) grid[gg.index] += gg.grad;
    // 3 points x 8 levels x 8 corners x 4 features, minus coincident entries
    EXPECT_GT(grid.size(), 400u);
    int checked = 0;
    for (auto it = grid.begin(); it != grid.end(); std::advance(it, std::min<size_t>(13, std::distance(it, grid.end())))) {
        const uint32_t i = it->first;
        const double h = 1e-6, v0 = s.w.grid[i];
        s.w.grid[i] = v0 + h;
        const double lp = linear_loss(s.w, s.q, s.c);
        s.w.grid[i] = v0 - h;
        const double lm = linear_loss(s.w, s.q, s.c);
        s.w.grid[i] = v0;
        expect_close(it->second, (lp - lm) / (2 * h), "grid[" + std::to_string(i) + "]");
        ++checked;
    }
    EXPECT_GT(checked, 30);
    // an entry no corner touches has zero derivative
    uint32_t untouched = 0;
    while (grid.count(untouched)) ++untouched;
    const double v0 = s.w.grid[untouched];
    s.w.grid[untouched] = v0 + 1e-3;
    const double lp = linear_loss(s.w, s.q, s.c);
    s.w.grid[untouched] = v0;
    EXPECT_EQ(lp, linear_loss(s.w, s.q, s.c));
}

TEST(Gradients, FeatureGradientMatchesFiniteDifferencesThroughTheMlp) {
    GradProbe s = make_setup(4);
    ForwardCacheT<double> cache;
    forward(s.w, s.q, Precision::fp32, &cache);
    GradientsT<double> g;
    g.reset();
    std::array<double, NB_MLP_INPUTS> dfeat{};
    backward(s.w, cache, s.c, g, &dfeat);
    // dL/dfeature_j = sum over corners of (dL/dgrid) / weight is not observable directly; instead check
    // the chain rule: sum_j dfeat_j * feature_j == sum_i dL/dgrid_i * grid_i (both are d/ds L(s * grid) at s=1)
    double lhs = 0, rhs = 0;
    for (uint32_t j = 0; j < NB_MLP_INPUTS; ++j) lhs += dfeat[j] * cache.features[j];
    for (const auto& gg : g.grid) rhs += gg.grad * s.w.grid[gg.index];
    EXPECT_NEAR(lhs, rhs, 1e-9 * std::max(1.0, std::fabs(lhs)));
}

TEST(Gradients, FloatBackwardMatchesDoubleBackward) {
    const NetworkWeights wf = test::large_value_network(5);
    const NetworkWeightsT<double> wd = to_double(wf);
    const SegmentQuery q = test_queries(1, 5)[0];
    Outputs cf{};
    OutputsT<double> cd{};
    for (uint32_t k = 0; k < NB_MLP_OUTPUTS; ++k) cf[k] = float(cd[k] = 0.25 * k - 1.0);
    ForwardCache cachef;
    ForwardCacheT<double> cached;
    const Outputs yf = forward(wf, q, Precision::fp32, &cachef);
    const OutputsT<double> yd = forward(wd, q, Precision::fp32, &cached);
    for (uint32_t k = 0; k < NB_MLP_OUTPUTS; ++k) EXPECT_NEAR(yf[k], yd[k], 1e-5);
    Gradients gf;
    GradientsT<double> gd;
    gf.reset();
    gd.reset();
    backward(wf, cachef, cf, gf);
    backward(wd, cached, cd, gd);
    double max_g = 0;
    for (double v : gd.mlp) max_g = std::max(max_g, std::fabs(v));
    // fp32 accumulation over <= 96 terms: 1e-4 of the largest gradient
    for (size_t i = 0; i < gd.mlp.size(); ++i) ASSERT_NEAR(gf.mlp[i], gd.mlp[i], 1e-4 * max_g) << i;
    ASSERT_EQ(gf.grid.size(), gd.grid.size());
    for (size_t i = 0; i < gd.grid.size(); ++i) {
        ASSERT_EQ(gf.grid[i].index, gd.grid[i].index);
        ASSERT_NEAR(gf.grid[i].grad, gd.grid[i].grad, 1e-4 * max_g + 1e-7);
    }
}

TEST(Losses, GradientsMatchFiniteDifferences) {
    // Prediction/target pairs away from the L1 kinks; hit (unmasked) and miss (masked).
    const Outputs y = {0.3f, 0.4f, 0.47f, 0.52f, 0.50f, 0.2f, 0.7f, 0.55f};
    const Targets hit = make_targets(true, 0.6f, vec3(0.0f, 0.6f, -0.8f), vec3(0.1f, 0.9f, 0.5f));
    for (bool linear : {true, false}) {
        LossConfig cfg;
        cfg.normal_linear = linear;
        Outputs g{};
        std::array<float, 8> per{};
        const float l = composite_loss(y, hit, cfg, &g, &per);
        float sum = 0;
        for (float v : per) sum += v;
        EXPECT_FLOAT_EQ(l, sum);
        for (uint32_t k = 0; k < NB_MLP_OUTPUTS; ++k) {
            // double finite differences of the per-slot loss; relative L2 with its denominator frozen
            const double h = 1e-4;
            auto slot_loss = [&](double yk) -> double {
                const double t = hit[k];
                if (k == NB_OUT_VISIBILITY) return 2.0 * -(t * std::log(yk) + (1 - t) * std::log(1 - yk));
                if (k == NB_OUT_DEPTH) return 2.0 * std::fabs(yk - t);
                if (k < NB_OUT_ALBEDO) return linear ? std::fabs(10 * yk - 4.5 - t) : std::fabs(yk - t);
                const double den = double(y[k]) * y[k] + 0.01;
                return (yk - t) * (yk - t) / den;
            };
            const double fd = (slot_loss(y[k] + h) - slot_loss(y[k] - h)) / (2 * h);
            // float evaluation of the loss: 1e-4 relative bound
            EXPECT_NEAR(g[k], fd, 1e-4 * std::max(1.0, std::fabs(fd))) << "slot " << k << " linear " << linear;
            EXPECT_NEAR(per[k], slot_loss(y[k]), 1e-5 * std::max(1.0, slot_loss(y[k]))) << "slot " << k;
        }
    }
    // BCE through the sigmoid gives y - t
    Outputs g{};
    composite_loss(y, hit, LossConfig{}, &g);
    EXPECT_NEAR(presigmoid_gradient(g[0], y[0]), 2.0f * (y[0] - 1.0f), 1e-5f);
    // miss: only visibility contributes
    Outputs gm{};
    const float lm = composite_loss(y, make_targets(false, 0, vec3(0.0f), vec3(0.0f)), LossConfig{}, &gm);
    EXPECT_NEAR(lm, 2.0f * -std::log(1.0f - 0.3f), 1e-6f);
    for (uint32_t k = 1; k < NB_MLP_OUTPUTS; ++k) EXPECT_EQ(gm[k], 0.0f);
    // BCE clamp keeps value and gradient finite at saturated outputs
    Outputs ys = y;
    ys[0] = 0.0f;
    const float ls = composite_loss(ys, hit, LossConfig{}, &g);
    EXPECT_TRUE(std::isfinite(ls) && std::isfinite(g[0]));
}

TEST(Forward, Fp16EmulationIsCloseToFp32) {
    // With the tcnn init (grid +-1e-4) and with the larger test weights: outputs differ by fp16
    // rounding only. Bound: 2e-3 absolute on every output (sigmoid slope <= 1/4 times ~8e-3 error of
    // the pre-activation accumulated through 5 layers of half-rounded 64-wide dot products).
    for (bool trained_like : {false, true}) {
        NeuralConfig cfg;
        cfg.log2_hash_size = 14;
        const NetworkWeights w = trained_like ? test::large_value_network(6) : create_network(cfg, 6);
        double max_diff = 0;
        for (const SegmentQuery& q : test_queries(200, 6)) {
            ForwardCache c16;
            const Outputs y32 = forward(w, q, Precision::fp32);
            const Outputs y16 = forward(w, q, Precision::fp16_emulated, &c16);
            for (uint32_t k = 0; k < NB_MLP_OUTPUTS; ++k) max_diff = std::max(max_diff, double(std::fabs(y32[k] - y16[k])));
            // emulated intermediate values are fp16-representable
            for (float f : c16.features) ASSERT_EQ(round_to_half(f), f);
            for (const auto& h : c16.hidden)
                for (float v : h) ASSERT_EQ(round_to_half(v), v);
        }
        EXPECT_LE(max_diff, 2e-3) << "trained_like " << trained_like;
        EXPECT_GT(max_diff, 0.0) << "fp16 emulation had no effect";
    }
}

TEST(Forward, BatchedMatchesSingle) {
    const NetworkWeights w = test::large_value_network(8);
    const auto qs = test_queries(300, 8);
    std::vector<Outputs> out(qs.size());
    forward_batch(w, qs, Precision::fp32, out, 3);
    std::vector<Outputs> dl(qs.size());
    for (size_t i = 0; i < qs.size(); ++i) {
        const Outputs y = forward(w, qs[i], Precision::fp32);
        for (uint32_t k = 0; k < NB_MLP_OUTPUTS; ++k) ASSERT_EQ(out[i][k], y[k]);
        for (uint32_t k = 0; k < NB_MLP_OUTPUTS; ++k) dl[i][k] = float(int(i % 5) - 2) * 0.1f + 0.01f * k;
    }
    std::vector<float> gm, gg;
    backward_batch(w, qs, dl, gm, gg, 3);
    Gradients ref;
    ref.reset();
    ForwardCache c;
    for (size_t i = 0; i < qs.size(); ++i) {
        forward(w, qs[i], Precision::fp32, &c);
        backward(w, c, dl[i], ref);
    }
    std::vector<float> ref_grid(w.grid.size(), 0.0f);
    for (const auto& e : ref.grid) ref_grid[e.index] += e.grad;
    float max_m = 0;
    for (float v : ref.mlp) max_m = std::max(max_m, std::fabs(v));
    for (size_t i = 0; i < gm.size(); ++i) ASSERT_NEAR(gm[i], ref.mlp[i], 1e-5f * max_m) << i;
    for (size_t i = 0; i < gg.size(); ++i) ASSERT_NEAR(gg[i], ref_grid[i], 1e-5f * max_m + 1e-7f) << i;
}

TEST(Network, InitialisationFollowsTcnn) {
    const NetworkWeights w = create_network(NeuralConfig{}, 42);
    EXPECT_EQ(w.grid.size(), 1348096u * 4u);
    EXPECT_EQ(w.mlp.size(), 19456u);
    float gmax = 0;
    for (float v : w.grid) gmax = std::max(gmax, std::fabs(v));
    EXPECT_LE(gmax, 1e-4f);
    EXPECT_GT(gmax, 0.9e-4f);
    for (uint32_t m = 0; m < NB_MLP_MATRICES; ++m) {
        const float s = std::sqrt(6.0f / float(nb_mlp_layer_inputs(m) + nb_mlp_layer_outputs(m)));
        float mmax = 0;
        for (uint32_t i = nb_mlp_layer_offset(m); i < nb_mlp_layer_offset(m) + nb_mlp_layer_inputs(m) * nb_mlp_layer_outputs(m); ++i)
            mmax = std::max(mmax, std::fabs(w.mlp[i]));
        EXPECT_LE(mmax, s);
        EXPECT_GT(mmax, 0.9f * s);
    }
    for (uint32_t i = nb_mlp_weight_index(4, NB_MLP_OUTPUTS, 0); i < NB_MLP_WEIGHT_COUNT; ++i) ASSERT_EQ(w.mlp[i], 0.0f);
    EXPECT_NO_THROW(validate_network(w));
    NetworkWeights bad = w;
    bad.mlp[17] = std::nanf("");
    EXPECT_THROW(validate_network(bad), Error);
    bad = w;
    bad.grid.pop_back();
    EXPECT_THROW(validate_network(bad), Error);
    // same seed, same weights; fp16 export rounds
    const NetworkWeights w2 = create_network(NeuralConfig{}, 42);
    EXPECT_EQ(w.mlp, w2.mlp);
    EXPECT_EQ(mlp_to_fp16(w)[5], float_to_half_bits(w.mlp[5]));
    EXPECT_EQ(grid_to_fp16(w).size(), w.grid.size());
}
