// The shared Adam update and training loss give the CPU's values on the GPU (label cuda): the hard cases
// of tests/neural/shared_training_test.cpp (zero/-0/subnormal gradients under both rules, t = 1 and late
// steps whose b^t is subnormal, huge gradients around the (1-b2) g^2 overflow, tiny ones, visibility at the
// clamped extremes) and random samples, evaluated by nvcc device code and by the host compiler. Skip
// decisions and step counters must be equal, skipped parameters untouched; values may differ only by FMA
// contraction and the device's powf/logf (bounds from the operands' scale below; the bit-identical share
// and the worst difference relative to its bound are printed).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>

#include "tests/cuda/shared_training_kernels.h"
#include "trainer/trainer_backend.h"

namespace nbvh::test {
namespace {

// Host vs device value within tol (equal bits, the same infinity, or |h - d| <= tol); counts bit-identical
// values and the worst difference relative to tol.
struct Compare {
    uint32_t same = 0, total = 0;
    double worst = 0.0; // max |h - d| / tol
    bool operator()(float h, float d, double tol) {
        total++;
        if (std::memcmp(&h, &d, 4) == 0) {
            same++;
            return true;
        }
        if (!std::isfinite(h) || !std::isfinite(d)) return false;
        const double e = std::fabs(double(h) - double(d));
        worst = std::max(worst, e / tol);
        return e <= tol;
    }
};

// Tolerances of the Adam update from the scale of its operands (an FMA or one ulp more in a step of
// cancellation moves a result by ~1e-7 of the operands, not of the result): 1e-6 of each operand scale,
// plus 1e-3 of the step for the bias factors (the device powf, a few ulp, in 1 - b2^t which cancels to
// 1e-3 at t = 1: ~1e-4 relative).
struct AdamTol {
    double m, v, w;
};
AdamTol adam_tolerance(const AdamCase& in, const AdamCase& host) {
    const GpuAdamRule& r = in.rule;
    const double ge = std::fabs(double(in.g)) + std::fabs(double(r.l2) * in.w);
    AdamTol t{};
    t.m = 1e-6 * (r.beta1 * std::fabs(double(in.m)) + (1.0 - r.beta1) * ge) + 1e-40;
    t.v = 1e-6 * (r.beta2 * double(in.v) + (1.0 - r.beta2) * ge * ge) + 1e-40;
    const double tt = double(host.t);
    const double lr_t = r.lr * std::sqrt(1.0 - std::pow(double(r.beta2), tt)) / (1.0 - std::pow(double(r.beta1), tt));
    const double s = lr_t / (std::sqrt(double(host.v)) + r.epsilon); // the step per unit of m
    t.w = 1e-6 * std::fabs(double(in.w)) + s * t.m + 1e-3 * std::fabs(s * host.m) + 1e-40;
    return t;
}

std::vector<AdamCase> adam_cases() {
    const float inf_g = std::numeric_limits<float>::max();
    const float gs[] = {0.0f, -0.0f, std::numeric_limits<float>::denorm_min(), 1e-30f, 1e-9f, 1e-7f, -1e-3f, 0.5f,
                        1.0f, -7.0f, 1e3f, -1e15f, 5.7e20f, 6e20f, -3e38f, inf_g};
    const GpuAdamRule rules[] = {{1e-2f, 0.9f, 0.999f, 1e-8f, 0.0f, 1u},  // grid
                                 {1e-2f, 0.9f, 0.999f, 1e-8f, 1e-8f, 0u}, // MLP
                                 {3e-4f, 0.9f, 0.99f, 1e-15f, 0.1f, 0u}};
    struct State { float w, m, v; uint32_t t; };
    const State states[] = {{1.0f, 0.0f, 0.0f, 0u}, {0.0f, 0.0f, 0.0f, 0u}, {-0.3f, 0.02f, 1e-3f, 57u},
                            {2.5f, -1e-4f, 3e-9f, 100000u}}; // t = 1e5: 0.999^t is ~3.5e-44, subnormal
    std::vector<AdamCase> out;
    for (const GpuAdamRule& r : rules)
        for (const State& s : states)
            for (float g : gs) out.push_back({s.w, s.m, s.v, s.t, g, r, 0u});
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (int i = 0; i < 4096; ++i) {
        const float g = u(rng) * std::pow(10.0f, 6.0f * u(rng));
        out.push_back({u(rng), 0.01f * u(rng), 1e-4f * std::fabs(u(rng)), uint32_t(i % 300), g, rules[i % 3], 0u});
    }
    return out;
}

std::vector<LossCase> loss_cases() {
    std::vector<LossCase> out;
    std::mt19937 rng(12);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const GpuLossConfig cfgs[] = {{2.0f, 2.0f, 1.0f, 1.0f, 1u, 1u}, {0.7f, 3.0f, 1.7f, 3.3f, 0u, 0u}};
    const float extremes[] = {0.0f, 1e-30f, 1.0f, std::nextafter(1.0f, 0.0f), 0.5f};
    for (int i = 0; i < 4096; ++i) {
        LossCase c{};
        for (uint32_t o = 0; o < NB_MLP_OUTPUTS; ++o) {
            c.y[o] = i < 200 ? extremes[(i + o) % 5] : u(rng);
            c.t[o] = u(rng);
        }
        c.t[NB_OUT_VISIBILITY] = (i / 2) % 2 ? 1.0f : 0.0f;
        c.cfg = cfgs[i % 2];
        out.push_back(c);
    }
    return out;
}

TEST(SharedTrainingOnDevice, AdamUpdateAndLossMatchTheHost) {
    if (!cuda_backend_available()) GTEST_SKIP() << "no usable CUDA GPU";
    std::vector<AdamCase> ha = adam_cases(), da = ha;
    std::vector<LossCase> hl = loss_cases(), dl = hl;
    apply_on_host(ha, hl);
    ASSERT_EQ(apply_on_device(da, dl), "");

    const std::vector<AdamCase> in = adam_cases();
    Compare adam;
    for (size_t i = 0; i < ha.size(); ++i) {
        const AdamCase &h = ha[i], &d = da[i];
        ASSERT_EQ(h.updated, d.updated) << "case " << i << " g " << h.g;
        ASSERT_EQ(h.t, d.t) << "case " << i;
        if (!h.updated) {
            EXPECT_TRUE(h.w == in[i].w && d.w == in[i].w && d.m == in[i].m && d.v == in[i].v) << "case " << i;
            continue;
        }
        const AdamTol tol = adam_tolerance(in[i], h);
        EXPECT_TRUE(adam(h.m, d.m, tol.m)) << "m, case " << i << " g " << h.g << ": " << h.m << " vs " << d.m;
        EXPECT_TRUE(adam(h.v, d.v, tol.v)) << "v, case " << i << " g " << h.g << ": " << h.v << " vs " << d.v;
        EXPECT_TRUE(adam(h.w, d.w, tol.w)) << "w, case " << i << " g " << h.g << ": " << h.w << " vs " << d.w;
        EXPECT_TRUE(std::isfinite(d.w) && std::isfinite(d.m)) << "case " << i;
    }
    // Loss: 3e-5 relative (logf a few ulps apart; the BCE gradient's former p - p^2 denominator cancelled near
    // p = 1 and measured 3.4e-5 apart on the H100 -- now p (1 - p)), plus, for values, 2e-6 of the linearised
    // normal's operands (10 y - 4.5 - t cancels; an FMA rounds 10 y differently).
    Compare loss;
    for (size_t i = 0; i < hl.size(); ++i) {
        const LossCase &h = hl[i], &d = dl[i];
        const float sc = h.cfg.normal_linear ? NB_NORMAL_LINEAR_SCALE : 1.0f;
        const float of = h.cfg.normal_linear ? NB_NORMAL_LINEAR_OFFSET : 0.0f;
        double floor_total = 1e-30;
        for (uint32_t o = 0; o < NB_MLP_OUTPUTS; ++o) {
            const bool normal = o >= NB_OUT_NORMAL && o < NB_OUT_ALBEDO;
            const double floor = normal ? 2e-6 * (sc * std::fabs(h.y[o]) + of + std::fabs(h.t[o])) : 1e-30;
            floor_total += nb_loss_weight(h.cfg, o) * floor;
            EXPECT_TRUE(loss(h.value[o], d.value[o], 3e-5 * std::fabs(h.value[o]) + floor))
                << "value " << o << ", case " << i << ": " << h.value[o] << " vs " << d.value[o];
            EXPECT_TRUE(loss(h.dl_dy[o], d.dl_dy[o], 3e-5 * std::fabs(h.dl_dy[o]) + 1e-30))
                << "dl_dy " << o << ", case " << i << ": " << h.dl_dy[o] << " vs " << d.dl_dy[o];
            EXPECT_TRUE(loss(h.dl_dz[o], d.dl_dz[o], 3e-5 * std::fabs(h.dl_dz[o]) + 1e-30))
                << "dl_dz " << o << ", case " << i << ": " << h.dl_dz[o] << " vs " << d.dl_dz[o];
            EXPECT_TRUE(std::isfinite(d.dl_dy[o]) && std::isfinite(d.dl_dz[o])) << "case " << i;
        }
        EXPECT_TRUE(loss(h.total, d.total, 3e-5 * std::fabs(h.total) + floor_total)) << "total, case " << i;
        EXPECT_TRUE(std::isfinite(d.total)) << "case " << i;
    }
    std::printf("adam: %u/%u values bit-identical, worst difference %.3g of its bound; loss: %u/%u, worst %.3g\n",
                adam.same, adam.total, adam.worst, loss.same, loss.total, loss.worst);
}

} // namespace
} // namespace nbvh::test
