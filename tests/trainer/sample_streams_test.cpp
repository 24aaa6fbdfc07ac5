// Statistics of the training sampler's random streams (trainer/pcg32.h SampleSlot): every (slot, attempt)
// draws from its own stream, so the CUDA sampler can run one slot's attempts in parallel. These check that
// the streams behave as independent draws: neighbouring slots are uncorrelated, and the survival roulette
// still keeps each leaf in proportion to (chance of being the first leaf) x (keep probability).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tests/trainer/test_cuts.h"
#include "tests/trainer/trainer_test_scenes.h"
#include "trainer/cpu/cpu_backend.h"
#include "trainer/training_asset.h"

namespace nbvh {
namespace {

using test::cut_at_depth;

double pearson(const std::vector<double>& x, const std::vector<double>& y) {
    double mx = 0, my = 0;
    for (size_t i = 0; i < x.size(); ++i) { mx += x[i]; my += y[i]; }
    mx /= double(x.size());
    my /= double(y.size());
    double sxy = 0, sxx = 0, syy = 0;
    for (size_t i = 0; i < x.size(); ++i) {
        sxy += (x[i] - mx) * (y[i] - my);
        sxx += (x[i] - mx) * (x[i] - mx);
        syy += (y[i] - my) * (y[i] - my);
    }
    return sxy / std::sqrt(sxx * syy);
}

struct Drawn {
    std::vector<TrainingSample> samples;
    std::vector<uint32_t> kept_per_leaf;
    uint64_t draws = 0;
};

Drawn draw(const TrainingAsset& asset, const TrainingCut& cut, uint64_t seed, uint32_t step, uint32_t n) {
    const TrainingCut* cuts[1] = {&cut};
    Drawn d;
    d.kept_per_leaf.assign(cut.size(), 0u);
    for (uint32_t i = 0; i < n; ++i) {
        const TrainingSample s = draw_training_sample(asset, cuts, {seed, step, i}, nullptr, d.draws);
        EXPECT_GE(s.leaf, 0);
        if (s.leaf < 0) continue;
        d.kept_per_leaf[size_t(s.leaf)]++;
        d.samples.push_back(s);
    }
    return d;
}

TEST(SampleStreams, NeighbouringSlotsAndStepsAreUncorrelated) {
    const Scene scene = test::scene_of(test::height_field(24, 0.3f, 1.0f, glm::vec3(0.0f)));
    const TrainingAsset asset = make_training_asset(scene, 0);
    TrainingCut cut = cut_at_depth(asset, 4);
    for (size_t l = 0; l < cut.size(); ++l) cut.keep_probability[l] = l % 2 ? 0.2f : 1.0f; // redraws
    const uint32_t n = 60000;
    const Drawn a = draw(asset, cut, 11, 5, n), b = draw(asset, cut, 11, 6, n);
    ASSERT_EQ(a.samples.size(), n);
    ASSERT_EQ(b.samples.size(), n);
    EXPECT_GT(a.draws, uint64_t(n) * 3 / 2); // most slots needed several attempts
    // |r| of independent samples: ~N(0, 1/n), sd 0.004; 0.02 is 5 sd.
    auto check = [&](auto value, const char* what) {
        std::vector<double> x, y, z;
        for (uint32_t i = 0; i + 1 < n; ++i) {
            x.push_back(value(a.samples[i]));
            y.push_back(value(a.samples[i + 1])); // next slot, same step
            z.push_back(value(b.samples[i]));     // same slot, next step
        }
        EXPECT_LT(std::abs(pearson(x, y)), 0.02) << what << ": slot i vs i + 1";
        EXPECT_LT(std::abs(pearson(x, z)), 0.02) << what << ": step 5 vs step 6";
    };
    check([](const TrainingSample& s) { return double(s.origin.x); }, "origin.x");
    check([](const TrainingSample& s) { return double(s.origin.z); }, "origin.z");
    check([](const TrainingSample& s) { return double(s.dir.y); }, "dir.y");
    check([](const TrainingSample& s) { return double(s.leaf); }, "leaf");
    check([](const TrainingSample& s) { return double(s.length); }, "length");
}

TEST(SampleStreams, AttemptStreamsAreUncorrelated) {
    // The raw streams: attempt k vs k + 1 of a slot, slot i vs i + 1 at one attempt, over their first
    // 8 numbers (an attempt draws at most 9), for the first attempts and some late ones.
    const uint32_t n = 40000;
    for (uint32_t k : {0u, 1u, 7u, 99999u}) {
        for (uint32_t j = 0; j < 8; ++j) {
            std::vector<double> x, next_attempt, next_slot;
            for (uint32_t i = 0; i < n; ++i) {
                auto nth = [j](Pcg32 r) { float v = 0; for (uint32_t q = 0; q <= j; ++q) v = r.next_float(); return double(v); };
                const SampleSlot s{42, 7, i}, s1{42, 7, i + 1};
                x.push_back(nth(s.attempt_rng(k)));
                next_attempt.push_back(nth(s.attempt_rng(k + 1)));
                next_slot.push_back(nth(s1.attempt_rng(k)));
            }
            EXPECT_LT(std::abs(pearson(x, next_attempt)), 0.025) << "attempt " << k << " number " << j;
            EXPECT_LT(std::abs(pearson(x, next_slot)), 0.025) << "attempt " << k << " number " << j;
        }
    }
}

TEST(SampleStreams, RouletteKeepsLeavesInProportion) {
    const Scene scene = test::scene_of(test::height_field(24, 0.3f, 1.0f, glm::vec3(0.0f)));
    const TrainingAsset asset = make_training_asset(scene, 0);
    TrainingCut cut = cut_at_depth(asset, 3);
    const uint32_t n = 60000;
    const Drawn plain = draw(asset, cut, 3, 1, n); // keep 1: how often each leaf is the first one
    std::vector<float> keep(cut.size());
    for (size_t l = 0; l < cut.size(); ++l) keep[l] = 0.05f + 0.95f * float(l % 4) / 3.0f;
    cut.keep_probability = keep;
    const Drawn kept = draw(asset, cut, 4, 1, n);
    double z_norm = 0;
    for (size_t l = 0; l < cut.size(); ++l) z_norm += double(plain.kept_per_leaf[l]) / n * keep[l];
    for (size_t l = 0; l < cut.size(); ++l) {
        const double p = double(plain.kept_per_leaf[l]) / n;
        const double expected = p * keep[l] / z_norm, seen = double(kept.kept_per_leaf[l]) / n;
        const double sd = std::sqrt(expected * (1 - expected) / n + (keep[l] / z_norm) * (keep[l] / z_norm) * p * (1 - p) / n);
        EXPECT_LT(std::abs(seen - expected), 5.0 * sd + 1e-9) << "leaf " << l << " keep " << keep[l];
    }
}

} // namespace
} // namespace nbvh
