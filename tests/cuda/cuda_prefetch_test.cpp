// The CUDA backend draws step k+1's batch while step k's network part runs (CudaBackendOptions::prefetch).
// These tests pin its contract: with unchanged keep probabilities a run is bit-identical to one without
// prefetch (deterministic mode: same rays, same weights); a cut change drops the batch drawn ahead (the
// step's rays are drawn on the new cut); a changed keep vector takes effect one step later. Skip without a GPU.
#include <gtest/gtest.h>

#include "tests/cuda/cuda_test_support.h"
#include "tests/trainer/trainer_test_scenes.h"
#include "trainer/cuda/cuda_backend.h"

namespace nbvh {
namespace {

struct StepRun {
    std::vector<std::vector<CudaDebugSample>> samples; // per step
    std::vector<StepStats> stats;
    neural::NetworkWeights weights;
};

struct StepInput {
    const TrainingCut* cut;
    uint64_t cut_version;
    uint32_t step = ~0u; // ~0: the input's index
    uint32_t batch = 3000;
    uint64_t seed = 5;
};

StepRun run_steps(const TrainingAsset& asset, bool prefetch, const std::vector<StepInput>& steps) {
    CudaBackendOptions opt;
    opt.deterministic = true;
    opt.prefetch = prefetch;
    auto b = make_cuda_backend_ex(asset, NeuralConfig{.log2_hash_size = 12}, neural::AdamConfig{}, opt, 3);
    StepRun r;
    for (uint32_t s = 0; s < steps.size(); ++s) {
        StepParams p;
        p.step = steps[s].step == ~0u ? s : steps[s].step;
        p.batch_size = steps[s].batch;
        p.seed = steps[s].seed;
        p.cuts = {steps[s].cut};
        p.cut_version = steps[s].cut_version;
        r.stats.push_back(b->step(p));
        std::vector<float> mg, gg;
        r.samples.emplace_back();
        b->read_last_step(r.samples.back(), mg, gg);
    }
    b->read_weights(r.weights);
    return r;
}

void expect_same_samples(const std::vector<CudaDebugSample>& a, const std::vector<CudaDebugSample>& b) {
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
        ASSERT_EQ(a[i].leaf, b[i].leaf) << "sample " << i;
        ASSERT_EQ(a[i].origin, b[i].origin) << "sample " << i;
        ASSERT_EQ(a[i].dir, b[i].dir) << "sample " << i;
        ASSERT_EQ(a[i].length, b[i].length) << "sample " << i;
        ASSERT_EQ(a[i].target, b[i].target) << "sample " << i;
    }
}

// Every call's samples, and the final weights, equal between the runs with and without prefetch.
void expect_same_runs(const StepRun& with, const StepRun& without, const std::vector<StepInput>& steps) {
    for (size_t s = 0; s < steps.size(); ++s) {
        SCOPED_TRACE("call " + std::to_string(s));
        ASSERT_EQ(with.samples[s].size(), steps[s].batch);
        expect_same_samples(with.samples[s], without.samples[s]);
        ASSERT_EQ(with.stats[s].leaves.size(), steps[s].cut->size());
        for (const CudaDebugSample& x : with.samples[s]) ASSERT_LT(x.leaf, int32_t(steps[s].cut->size()));
    }
    EXPECT_EQ(with.weights.mlp, without.weights.mlp);
    EXPECT_EQ(with.weights.grid, without.weights.grid);
}

// The prefetch tests' asset: a 32 x 32 height field.
struct HeightField : test::MeshAsset {
    HeightField() : test::MeshAsset(test::height_field(32, 0.2f, 1.0f, glm::vec3(0.0f))) {}
};

TEST(CudaPrefetch, SameRaysAndWeightsAsWithoutPrefetch) {
    REQUIRE_GPU();
    const HeightField h;
    const TrainingAsset& asset = h.asset;
    TrainingCut cut = test::cut_at_depth(asset, 5);
    for (size_t i = 0; i < cut.size(); ++i) cut.keep_probability[i] = i % 3 == 0 ? 0.25f : 1.0f; // roulette redraws
    const std::vector<StepInput> steps(5, StepInput{&cut, 1});
    const StepRun with = run_steps(asset, true, steps), without = run_steps(asset, false, steps);
    expect_same_runs(with, without, steps);
    for (size_t s = 0; s < steps.size(); ++s) { // and the statistics the host splits by
        SCOPED_TRACE("step " + std::to_string(s));
        EXPECT_EQ(with.stats[s].draws, without.stats[s].draws);
        EXPECT_EQ(with.stats[s].loss.total, without.stats[s].loss.total);
        ASSERT_EQ(with.stats[s].leaves.size(), without.stats[s].leaves.size());
        for (size_t i = 0; i < with.stats[s].leaves.size(); ++i) {
            EXPECT_EQ(with.stats[s].leaves[i].draws, without.stats[s].leaves[i].draws);
            EXPECT_EQ(with.stats[s].leaves[i].samples, without.stats[s].leaves[i].samples);
        }
    }
}

TEST(CudaPrefetch, CutChangeDropsTheBatchDrawnAhead) {
    REQUIRE_GPU();
    const HeightField h;
    const TrainingAsset& asset = h.asset;
    const TrainingCut coarse = test::cut_at_depth(asset, 3), fine = test::cut_at_depth(asset, 6);
    ASSERT_NE(coarse.size(), fine.size());
    const std::vector<StepInput> steps{{&coarse, 1}, {&fine, 2}, {&fine, 2}, {&coarse, 3}};
    expect_same_runs(run_steps(asset, true, steps), run_steps(asset, false, steps), steps);
}

// A batch drawn ahead is used only for the step index, batch size and seed it was drawn for: a trainer
// that repeats or skips a step index, or changes the batch or the seed, gets a batch drawn anew.
TEST(CudaPrefetch, OtherStepBatchOrSeedDrawsAnew) {
    REQUIRE_GPU();
    const HeightField h;
    const TrainingAsset& asset = h.asset;
    TrainingCut cut = test::cut_at_depth(asset, 5);
    for (size_t i = 0; i < cut.size(); ++i) cut.keep_probability[i] = i % 4 == 0 ? 0.3f : 1.0f;
    auto in = [&](uint32_t step, uint32_t batch, uint64_t seed) { return StepInput{&cut, 1, step, batch, seed}; };
    const std::vector<StepInput> steps{in(0, 3000, 5), in(1, 3000, 5), in(1, 3000, 5), in(2, 2000, 5),
                                       in(3, 4000, 5), in(4, 4000, 6), in(7, 4000, 6), in(8, 4000, 6)};
    expect_same_runs(run_steps(asset, true, steps), run_steps(asset, false, steps), steps);
}

// The batch of step k+1 is drawn during step k with step k's keep probabilities: a new keep vector
// passed at step k+1 shapes the rays of step k+2.
TEST(CudaPrefetch, NewKeepProbabilitiesActOneStepLater) {
    REQUIRE_GPU();
    const HeightField h;
    const TrainingAsset& asset = h.asset;
    TrainingCut all = test::cut_at_depth(asset, 5), few = all;
    for (size_t i = 0; i < few.size(); ++i) few.keep_probability[i] = i % 2 == 0 ? 0.05f : 1.0f;
    // A keep change is not a cut change: same cut_version.
    const StepRun with = run_steps(asset, true, {{&all, 1}, {&few, 1}, {&few, 1}});
    const StepRun lagged = run_steps(asset, false, {{&all, 1}, {&all, 1}, {&few, 1}});
    for (size_t s = 0; s < 3; ++s) {
        SCOPED_TRACE("step " + std::to_string(s));
        expect_same_samples(with.samples[s], lagged.samples[s]);
    }
}

} // namespace
} // namespace nbvh
