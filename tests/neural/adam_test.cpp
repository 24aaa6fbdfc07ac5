// Adam against hand-worked steps (tcnn semantics: folded bias correction, per-parameter step counters,
// zero-gradient grid entries skipped, L2 on MLP weights only) and the ExponentialDecay schedule.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/neural/adam.h"

using namespace nbvh::neural;

namespace {
NetworkWeights tiny_weights() {
    NetworkWeights w;
    w.mlp.assign(NB_MLP_WEIGHT_COUNT, 0.0f);
    w.grid.assign(8, 0.0f);
    return w;
}
} // namespace

TEST(Adam, HandWorkedSteps) {
    AdamConfig cfg; // lr 1e-2, b1 0.9, b2 0.999, eps 1e-8, l2 1e-8
    cfg.l2_reg = 0.0f;
    NetworkWeights w = tiny_weights();
    w.mlp[0] = 1.0f;
    w.mlp[1] = -2.0f;
    Adam adam(cfg, w.mlp.size(), w.grid.size());
    std::vector<float> gm(w.mlp.size(), 0.0f), gg(w.grid.size(), 0.0f);
    gm[0] = 0.5f;
    gm[1] = -4.0f;
    adam.step(w, gm, gg);
    // step 1, w0: m = 0.1*0.5 = 0.05, v = 0.001*0.25 = 2.5e-4, lr_t = 0.01*sqrt(0.001)/0.1 = 3.16228e-3,
    // update = lr_t * m / (sqrt(v) + eps) = 3.16228e-3 * 0.05 / (0.0158114 + 1e-8) = 0.0099999937
    EXPECT_NEAR(w.mlp[0], 1.0f - 0.0099999937f, 1e-7f);
    // w1: m = -0.4, v = 0.016, sqrt(v) = 0.126491; update = 3.16228e-3 * -0.4 / 0.126491 = -0.01 (+eps)
    EXPECT_NEAR(w.mlp[1], -2.0f + 0.01f, 1e-7f);
    // (1 - 0.9f) and (1 - 0.999f) are not exact in fp32: 1e-5 relative
    EXPECT_NEAR(adam.mlp_m()[0], 0.05f, 5e-7f);
    EXPECT_NEAR(adam.mlp_v()[0], 2.5e-4f, 5e-9f);
    EXPECT_EQ(adam.mlp_t()[0], 1u);
    // step 2 with gradient 0.5 again on w0: m = 0.9*0.05 + 0.05 = 0.095, v = 0.999*2.5e-4 + 2.5e-4
    // = 4.9975e-4, lr_t = 0.01*sqrt(1-0.998001)/(1-0.81) = 0.01*0.0447102/0.19 = 2.353169e-3,
    // update = 2.353169e-3 * 0.095 / 0.02235509 = 0.0100000 (a constant gradient moves by lr each step)
    gm[1] = 0.0f;
    adam.step(w, gm, gg);
    EXPECT_NEAR(w.mlp[0], 1.0f - 0.0099999937f - 0.01f, 2e-7f);
    // w1 got gradient 0 but is an MLP weight: still updated with its decayed moments:
    // m = -0.36, v = 0.015984, lr_t = 2.353169e-3, update = 2.353169e-3 * -0.36 / 0.1264278 = -6.7007e-3
    EXPECT_NEAR(w.mlp[1], -2.0f + 0.01f + 6.7007e-3f, 2e-6f);
    EXPECT_EQ(adam.mlp_t()[1], 2u);
    EXPECT_EQ(adam.steps_taken(), 2u);
}

TEST(Adam, SparseGridEntriesAndL2) {
    AdamConfig cfg;
    cfg.l2_reg = 0.1f; // large, to see it
    cfg.loss_scale = 128.0f;
    NetworkWeights w = tiny_weights();
    w.mlp[3] = 2.0f;
    w.grid[0] = 1.0f;
    w.grid[1] = 1.0f;
    Adam adam(cfg, w.mlp.size(), w.grid.size());
    std::vector<float> gm(w.mlp.size(), 0.0f), gg(w.grid.size(), 0.0f);
    gg[0] = 128.0f * 0.5f; // divided by the loss scale -> 0.5
    adam.step(w, gm, gg);
    // grid entry 0: first step moves by lr (no L2 on the grid)
    EXPECT_NEAR(w.grid[0], 1.0f - 0.01f, 1e-7f);
    // grid entry 1 had gradient exactly 0: skipped, no step counted
    EXPECT_EQ(w.grid[1], 1.0f);
    EXPECT_EQ(adam.grid_t()[1], 0u);
    EXPECT_EQ(adam.grid_t()[0], 1u);
    // MLP weight 3 had gradient 0 but L2 adds 0.1 * 2 = 0.2: moves by lr
    EXPECT_NEAR(w.mlp[3], 2.0f - 0.01f, 1e-7f);
    // a weight at 0 with gradient 0 stays exactly 0 (padding rows stay 0)
    EXPECT_EQ(w.mlp[4], 0.0f);
    // next step touches entry 1 for the first time: its own bias correction starts at t = 1
    gg[0] = 0.0f;
    gg[1] = -128.0f;
    adam.step(w, gm, gg);
    EXPECT_NEAR(w.grid[1], 1.0f + 0.01f, 1e-7f);
    EXPECT_EQ(adam.grid_t()[1], 1u);
    EXPECT_EQ(adam.grid_t()[0], 1u);
    EXPECT_NEAR(w.grid[0], 1.0f - 0.01f, 1e-7f); // skipped this time
}

TEST(Adam, ExponentialDecaySchedule) {
    AdamConfig cfg; // start 10000, interval 2000, base 0.33
    EXPECT_FLOAT_EQ(lr_at_step(cfg, 0), 1e-2f);
    EXPECT_FLOAT_EQ(lr_at_step(cfg, 9999), 1e-2f); // N-BVH's 10k steps never decay
    EXPECT_FLOAT_EQ(lr_at_step(cfg, 10000), 3.3e-3f);
    EXPECT_FLOAT_EQ(lr_at_step(cfg, 11999), 3.3e-3f);
    EXPECT_NEAR(lr_at_step(cfg, 12000), 1e-2f * 0.33f * 0.33f, 1e-9f);
    cfg.decay_end = 12000;
    EXPECT_NEAR(lr_at_step(cfg, 50000), 1e-2f * 0.33f * 0.33f, 1e-9f);
}

#include "engine/neural/losses.h"

TEST(Adam, FewStepsOnAFixedBatchReduceTheCompositeLoss) {
    // Sign conventions end to end: loss gradient (post-sigmoid) -> backward -> Adam must descend.
    nbvh::NeuralConfig cfg;
    cfg.log2_hash_size = 14;
    NetworkWeights w = create_network(cfg, 11);
    std::vector<SegmentQuery> qs(64);
    std::vector<Targets> ts(qs.size());
    for (size_t i = 0; i < qs.size(); ++i) {
        const float a = float(i) / float(qs.size());
        qs[i].points = {vec3(a, 0.2f, 0.3f), vec3(0.5f, a, 0.5f), vec3(1.0f - a, 0.8f, 0.7f)};
        const bool hit = (i % 3) != 0;
        ts[i] = make_targets(hit, a, normalize(vec3(a - 0.5f, 1.0f, 0.2f)), vec3(a, 0.5f, 1.0f - a));
    }
    AdamConfig acfg;
    Adam adam(acfg, w.mlp.size(), w.grid.size());
    const LossConfig lcfg;
    auto total_loss = [&](std::vector<Outputs>* grads) {
        std::vector<Outputs> y(qs.size());
        forward_batch(w, qs, Precision::fp32, y, 1);
        double l = 0;
        for (size_t i = 0; i < qs.size(); ++i) {
            Outputs g{};
            l += composite_loss(y[i], ts[i], lcfg, &g);
            if (grads) {
                for (float& v : g) v /= float(qs.size());
                (*grads)[i] = g;
            }
        }
        return l / double(qs.size());
    };
    const double l0 = total_loss(nullptr);
    std::vector<Outputs> dl(qs.size());
    std::vector<float> gm, gg;
    for (int step = 0; step < 30; ++step) {
        total_loss(&dl);
        backward_batch(w, qs, dl, gm, gg, 1);
        adam.step(w, gm, gg);
    }
    const double l1 = total_loss(nullptr);
    EXPECT_LT(l1, 0.5 * l0) << "loss " << l0 << " -> " << l1;
}
