// The shared per-parameter Adam update and training loss (engine/neural/shared/, called by the CPU and
// CUDA trainers) against the values their headers document, on the hard cases: zero gradients with and
// without the sparse skip, the t = 1 bias correction, huge and tiny gradients, the fp16 copy's edges,
// visibility at the clamped 0/1 extremes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "engine/neural/fp16.h"
#include "engine/neural/shared/adam_update.h"
#include "engine/neural/shared/training_loss.h"

using namespace nbvh;

namespace {

constexpr GpuAdamRule kRule{1e-2f, 0.9f, 0.999f, 1e-8f, 0.0f, 1u};

struct Param {
    float w = 1.0f, m = 0.0f, v = 0.0f;
    uint32_t t = 0;
    bool step(float g, const GpuAdamRule& r = kRule) { return nb_adam_update(w, m, v, t, g, r, nullptr, nullptr, 0u); }
};

bool all_finite(const float* x, int n) {
    for (int i = 0; i < n; ++i)
        if (!std::isfinite(x[i])) return false;
    return true;
}

} // namespace

TEST(AdamUpdate, ZeroGradientIsSkippedOnlyWithTheSparseRule) {
    GpuAdamRule r = kRule;
    r.l2 = 0.1f;
    for (float zero : {0.0f, -0.0f}) {
        Param p{2.0f, 0.25f, 0.5f, 7u};
        EXPECT_FALSE(p.step(zero, r));
        EXPECT_EQ(p.w, 2.0f); // nothing moves, L2 included: no sample touched the entry
        EXPECT_EQ(p.m, 0.25f);
        EXPECT_EQ(p.v, 0.5f);
        EXPECT_EQ(p.t, 7u);
    }
    // The smallest subnormal is not zero: updated.
    Param tiny;
    EXPECT_TRUE(tiny.step(std::numeric_limits<float>::denorm_min(), r));
    EXPECT_EQ(tiny.t, 1u);
    // Matrix rule: a zero gradient still decays the moments, counts a step and applies L2
    // (g = 0.1 * 2 = 0.2, a first step: moves by lr).
    r.skip_zero = 0u;
    Param mlp{2.0f, 0.0f, 0.0f, 0u};
    EXPECT_TRUE(mlp.step(0.0f, r));
    EXPECT_EQ(mlp.t, 1u);
    EXPECT_NEAR(mlp.w, 2.0f - 0.01f, 2e-7f);
    // A weight at 0 with gradient 0 stays exactly 0 under the matrix rule (the padding rows).
    Param pad{0.0f, 0.0f, 0.0f, 0u};
    EXPECT_TRUE(pad.step(0.0f, r));
    EXPECT_EQ(pad.w, 0.0f);
}

TEST(AdamUpdate, FirstStepBiasCorrectionMovesByTheLearningRate) {
    EXPECT_EQ(nb_adam_bias_sqrt(0.999f, 1u), std::sqrt(1.0f - 0.999f));
    EXPECT_EQ(nb_adam_bias_div(0.9f, 1u), 1.0f - 0.9f);
    EXPECT_EQ(nb_adam_bias_div(0.9f, 0u), 0.0f); // t = 0 never reaches the update: t is incremented first
    // t = 1: m = (1-b1) g, v = (1-b2) g^2, lr_t = lr sqrt(1-b2)/(1-b1): the step is
    // lr sign(g) k / (k + eps) with k = sqrt(1-b2) |g|, i.e. lr sign(g) for |g| >> eps / sqrt(1-b2) = 3.2e-7
    // and lr k / eps for |g| << 3.2e-7.
    for (float g : {1e-9f, 1e-7f, -1e-3f, -0.5f, 1.0f, 1e3f, -1e15f, 1e18f}) {
        Param p;
        ASSERT_TRUE(p.step(g));
        EXPECT_EQ(p.t, 1u);
        EXPECT_NEAR(p.m, 0.1f * g, 1e-6f * std::fabs(g)) << g;
        const double k = std::sqrt(double(1.0f - 0.999f)) * std::fabs(double(g));
        EXPECT_NEAR(p.w, 1.0 - 1e-2 * std::copysign(1.0, g) * k / (k + 1e-8), 2e-7) << g;
    }
    // A per-t table gives the same bits as computing the factors (the CPU's cache vs CUDA's powf).
    float bs[4], bd[4];
    for (uint32_t t = 0; t < 4; ++t) {
        bs[t] = nb_adam_bias_sqrt(kRule.beta2, t);
        bd[t] = nb_adam_bias_div(kRule.beta1, t);
    }
    Param a, b;
    for (float g : {0.3f, -2.0f, 0.7f, 5.0f, -1.0f}) { // the 5th step (t = 5) is outside the table
        a.step(g);
        nb_adam_update(b.w, b.m, b.v, b.t, g, kRule, bs, bd, 4u);
        EXPECT_EQ(a.w, b.w);
        EXPECT_EQ(a.m, b.m);
        EXPECT_EQ(a.v, b.v);
    }
    EXPECT_EQ(b.t, 5u);
}

TEST(AdamUpdate, HugeAndTinyGradientsKeepTheWeightFinite) {
    // |g| > sqrt(FLT_MAX / (1 - b2)) = 5.8e20: (1 - b2) g^2 overflows, v = inf and the parameter stops
    // moving (documented; float arithmetic, as tcnn).
    for (float g : {6e20f, -3e38f, std::numeric_limits<float>::max()}) {
        Param p;
        ASSERT_TRUE(p.step(g));
        EXPECT_TRUE(std::isinf(p.v)) << g;
        EXPECT_TRUE(std::isfinite(p.m)) << g;
        EXPECT_EQ(p.w, 1.0f) << g;
        p.step(1.0f); // and for good: v stays inf
        EXPECT_EQ(p.w, 1.0f) << g;
    }
    // 5.7e20, just below: v finite, an ordinary first step of lr.
    Param big;
    big.step(5.7e20f);
    EXPECT_TRUE(std::isfinite(big.v));
    EXPECT_NEAR(big.w, 0.99f, 3e-7f);
    // |g| < ~1e-21: (1 - b2) g^2 underflows to 0, the step lr_t m / eps is far below w's resolution.
    Param small;
    small.step(1e-30f);
    EXPECT_EQ(small.v, 0.0f);
    EXPECT_NEAR(small.m, 1e-31f, 1e-36f);
    EXPECT_EQ(small.w, 1.0f);
    EXPECT_EQ(small.t, 1u);
}

TEST(AdamUpdate, Fp32MasterAccumulatesStepsBelowTheFp16Resolution) {
    // lr 1e-4 < half an fp16 ulp at 1 (2^-11 = 4.9e-4): one step leaves the fp16 copy at 1, three steps
    // (w = 0.9997) round it to the next half below 1 (0.99951171875).
    GpuAdamRule r = kRule;
    r.lr = 1e-4f;
    Param p;
    p.step(1.0f, r);
    EXPECT_LT(p.w, 1.0f);
    EXPECT_EQ(float_to_half_bits(p.w), float_to_half_bits(1.0f));
    p.step(1.0f, r);
    p.step(1.0f, r);
    EXPECT_NEAR(p.w, 0.9997f, 1e-6f);
    EXPECT_EQ(round_to_half(p.w), 0.99951171875f);
    // The copy's range is the caller's: an update across 65520 leaves a finite master and an infinite copy.
    r.lr = 1.0f;
    Param edge{65519.5f, 0.0f, 0.0f, 0u};
    edge.step(-1.0f, r);
    EXPECT_NEAR(edge.w, 65520.5f, 0.01f);
    EXPECT_EQ(float_to_half_bits(edge.w), 0x7C00u);
    EXPECT_EQ(round_to_half(65519.0f), 65504.0f);
}

TEST(TrainingLoss, VisibilityExtremesHaveFiniteClampedValuesAndGradients) {
    const GpuLossConfig c{2.0f, 2.0f, 1.0f, 1.0f, 1u, 1u};
    const float lo = NB_BCE_CLAMP, hi = 1.0f - NB_BCE_CLAMP;
    // y0 = 0 exactly (a saturated sigmoid), subnormal, 1 and the float just below 1: all clamped.
    for (float y0 : {0.0f, 1e-30f, 1.0f, std::nextafter(1.0f, 0.0f)}) {
        for (float t0 : {0.0f, 1.0f}) {
            float d = 0.0f;
            const float l = nb_loss_bce(y0, t0, d);
            const float p = y0 < 0.5f ? lo : hi;
            // value -(t log p + (1-t) log(1-p)), gradient -(t - p)/(p (1 - p)), at the clamped p
            EXPECT_NEAR(l, -(t0 * std::log(p) + (1.0f - t0) * std::log(1.0f - p)), 1e-4f) << y0 << " " << t0;
            EXPECT_TRUE(std::isfinite(d));
            // p (1 - p) does not cancel near p = 1 (p - p^2, the official form, is 1e-5 off there): a few ulps
            const double ref = -(t0 - double(p)) / (double(p) * (1.0 - double(p)));
            EXPECT_NEAR(d, ref, 1e-6 * std::fabs(ref)) << y0 << " " << t0;
            EXPECT_LE(std::fabs(d), 1.001e5f);
            EXPECT_EQ(d < 0.0f, t0 == 1.0f); // always towards the target
            // The pre-sigmoid gradient of a saturated output is exactly 0, never NaN.
            const float dz = nb_presigmoid_gradient(d, y0);
            EXPECT_TRUE(std::isfinite(dz));
            if (y0 == 0.0f || y0 == 1.0f) {
                EXPECT_EQ(dz, 0.0f);
            }
        }
    }
    // The two worst cases by hand: y = 0 with a hit (-log 1e-5 = 11.5129, -1/p = -1e5) and a confident
    // correct hit (-log(1 - 1e-5) ~ 1e-5, -1/p ~ -1).
    float d = 0.0f;
    EXPECT_NEAR(nb_loss_bce(0.0f, 1.0f, d), 11.5129f, 1e-3f);
    EXPECT_NEAR(d, -1e5f, 1.0f);
    EXPECT_NEAR(nb_loss_bce(1.0f, 1.0f, d), 1e-5f, 1e-7f);
    EXPECT_NEAR(d, -1.0f, 1e-4f);
    // A whole sample at the extremes: every output 0 or 1, hit and miss: finite everywhere.
    for (float yv : {0.0f, 1.0f}) {
        for (float tv : {0.0f, 1.0f}) {
            float y[8], t[8], u[8], g[8];
            for (int i = 0; i < 8; ++i) {
                y[i] = yv;
                t[i] = i == 0 ? tv : 1.0f - yv;
            }
            const float total = nb_composite_loss(y, t, c, u, g);
            EXPECT_TRUE(std::isfinite(total));
            EXPECT_TRUE(all_finite(u, 8) && all_finite(g, 8));
        }
    }
}

TEST(TrainingLoss, TermsWeightsAndMaskingAsDocumented) {
    float d = 0.0f;
    // L1: sign, 0 at equality.
    EXPECT_EQ(nb_loss_l1(0.25f, 0.75f, d), 0.5f);
    EXPECT_EQ(d, -1.0f);
    EXPECT_EQ(nb_loss_l1(0.5f, 0.5f, d), 0.0f);
    EXPECT_EQ(d, 0.0f);
    // Linearised normal: N(y) = 10 y - 4.5; y = 0.5 decodes the target 0.5 exactly, y = 0.55 is 0.5 off.
    EXPECT_EQ(nb_loss_normal(0.5f, 0.5f, 1u, d), 0.0f);
    EXPECT_EQ(d, 0.0f);
    EXPECT_NEAR(nb_loss_normal(0.55f, 0.5f, 1u, d), 0.5f, 1e-6f);
    EXPECT_EQ(d, 10.0f);
    EXPECT_NEAR(nb_loss_normal(0.55f, 0.5f, 0u, d), 0.05f, 1e-6f);
    EXPECT_EQ(d, 1.0f);
    // Relative L2 with the constant denominator: y = 0, t = 1: 1 / 0.01 and -2 / 0.01.
    EXPECT_NEAR(nb_loss_rel_l2(0.0f, 1.0f, d), 100.0f, 1e-3f);
    EXPECT_NEAR(d, -200.0f, 1e-3f);
    // y = 1, t = 0: 1 / 1.01 and 2 / 1.01 (not the true derivative, which also differentiates y^2).
    EXPECT_NEAR(nb_loss_rel_l2(1.0f, 0.0f, d), 1.0f / 1.01f, 1e-6f);
    EXPECT_NEAR(d, 2.0f / 1.01f, 1e-6f);

    // Composite: weighted total = sum of w_i value_i in slot order, dL/dy = w_i d_i, values unweighted.
    const GpuLossConfig c{2.0f, 3.0f, 0.5f, 4.0f, 1u, 1u};
    const float y[8] = {0.3f, 0.2f, 0.55f, 0.45f, 0.5f, 0.1f, 0.9f, 0.0f};
    float t[8] = {1.0f, 0.6f, 0.5f, 0.5f, 0.5f, 0.2f, 0.8f, 1.0f};
    float u[8], g[8];
    const float total = nb_composite_loss(y, t, c, u, g);
    float sum = 0.0f;
    for (uint32_t i = 0; i < 8; ++i) {
        float di = 0.0f, ui = 0.0f;
        if (i == 0) {
            ui = nb_loss_bce(y[i], t[i], di);
        } else if (i == 1) {
            ui = nb_loss_l1(y[i], t[i], di);
        } else if (i < 5) {
            ui = nb_loss_normal(y[i], t[i], 1u, di);
        } else {
            ui = nb_loss_rel_l2(y[i], t[i], di);
        }
        EXPECT_EQ(u[i], ui) << i;
        EXPECT_EQ(g[i], nb_loss_weight(c, i) * di) << i;
        sum += nb_loss_weight(c, i) * ui;
    }
    EXPECT_EQ(total, sum);
    EXPECT_EQ(nb_loss_weight(c, NB_OUT_DEPTH), 3.0f);
    EXPECT_EQ(nb_loss_weight(c, NB_OUT_NORMAL + 2), 0.5f);
    EXPECT_EQ(nb_loss_weight(c, NB_OUT_ALBEDO), 4.0f);
    // A miss (t0 < 0.5) masks depth, normal and albedo: value and gradient exactly 0, visibility kept.
    t[0] = 0.0f;
    const float masked = nb_composite_loss(y, t, c, u, g);
    for (uint32_t i = 1; i < 8; ++i) {
        EXPECT_EQ(u[i], 0.0f) << i;
        EXPECT_EQ(g[i], 0.0f) << i;
    }
    EXPECT_EQ(masked, 2.0f * u[0]);
    EXPECT_GT(g[0], 0.0f);
    // Without masking the other terms count for a miss too.
    const GpuLossConfig unmasked{2.0f, 3.0f, 0.5f, 4.0f, 1u, 0u};
    EXPECT_GT(nb_composite_loss(y, t, unmasked, u, g), masked);
    EXPECT_NE(g[NB_OUT_DEPTH], 0.0f);
}
