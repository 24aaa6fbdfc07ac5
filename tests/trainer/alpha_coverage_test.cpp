// Alpha-tested surfaces in the trainer's ground truth (trainer/ground_truth.cpp alpha_covers): a MASK
// cut-out lets rays through where its texture's alpha is below the cutoff, a BLEND surface stops a
// fraction alpha of the rays, independently per sample and triangle, reproducibly for a sample's key,
// and none through its back face when single-sided.
#include <gtest/gtest.h>

#include "tests/trainer/trainer_test_scenes.h"
#include "trainer/ground_truth.h"

using namespace nbvh;

namespace {

// Ground truth of the ray straight down (-z) through (x, y) from z = 1, segment length 2.
GroundTruth down_at(const TrainingAsset& a, float x, float y, const SampleSlot& key) {
    return trace_ground_truth(a, {x, y, 1.0f}, {0, 0, -1}, 0.0f, 2.0f, key);
}

} // namespace

TEST(AlphaCoverage, OnlyAlphaTestedAssetsFilterHits) {
    const Scene alpha = test::alpha_quads_scene();
    EXPECT_TRUE(make_training_asset(alpha, 0).alpha_tested);
    Scene opaque = alpha;
    for (Material& m : opaque.materials) m.alpha_mode = AlphaMode::opaque;
    const TrainingAsset a = make_training_asset(opaque, 0);
    EXPECT_FALSE(a.alpha_tested);
    // Opaque: the alpha factor and texture are ignored (glTF), every ray stops at the first quad.
    for (float x : {0.25f, 0.75f, 1.7f}) {
        const GroundTruth gt = down_at(a, x, 0.5f, SampleSlot{1, 2, 3});
        ASSERT_TRUE(gt.hit);
        EXPECT_NEAR(gt.t_hit, 1.0f, 1e-6f) << x;
    }
}

TEST(AlphaCoverage, MaskCutsOutWhereTheTextureAlphaIsBelowTheCutoff) {
    const Scene scene = test::alpha_quads_scene();
    const TrainingAsset a = make_training_asset(scene, 0);
    for (uint32_t slot = 0; slot < 16; ++slot) {
        const SampleSlot key{5, 7, slot};
        // Left texel centre (alpha 0): through the hole to the backdrop at z = -0.5.
        const GroundTruth hole = down_at(a, 0.25f, 0.5f, key);
        ASSERT_TRUE(hole.hit);
        EXPECT_NEAR(hole.t_hit, 1.5f, 1e-6f);
        // Right texel centre (alpha 1) and just right of the bilinear midpoint (alpha ~0.52 >= 0.5).
        EXPECT_NEAR(down_at(a, 0.75f, 0.5f, key).t_hit, 1.0f, 1e-6f);
        EXPECT_NEAR(down_at(a, 0.51f, 0.5f, key).t_hit, 1.0f, 1e-6f);
        EXPECT_NEAR(down_at(a, 0.49f, 0.5f, key).t_hit, 1.5f, 1e-6f); // alpha ~0.48
        // The albedo comes from the surface that was hit (the backdrop has no texture).
        EXPECT_NEAR(hole.albedo.x, 0.8f, 1e-6f);
    }
}

TEST(AlphaCoverage, BlendStopsAFractionAlphaOfTheRays) {
    const Scene scene = test::alpha_quads_scene();
    const TrainingAsset a = make_training_asset(scene, 0);
    constexpr uint32_t N = 8000;
    uint32_t stopped = 0, behind = 0, repeat_same = 0;
    for (uint32_t slot = 0; slot < N; ++slot) {
        const SampleSlot key{11, slot / 100, slot % 100};
        const GroundTruth gt = down_at(a, 1.7f, 0.3f, key);
        ASSERT_TRUE(gt.hit);
        if (std::fabs(gt.t_hit - 1.0f) < 1e-6f) stopped++;
        else if (std::fabs(gt.t_hit - 1.5f) < 1e-6f) behind++;
        repeat_same += down_at(a, 1.7f, 0.3f, key).t_hit == gt.t_hit;
    }
    EXPECT_EQ(stopped + behind, N);
    // Binomial(8000, 0.3): standard deviation 0.0051; 0.02 is four of them.
    EXPECT_NEAR(double(stopped) / N, 0.3, 0.02);
    EXPECT_EQ(repeat_same, N); // a sample's draw is a function of its key
    // Different steps of one slot decide independently (not one fixed answer per slot).
    uint32_t changes = 0;
    bool last = down_at(a, 1.7f, 0.3f, SampleSlot{11, 0, 4}).t_hit < 1.25f;
    for (uint32_t step = 1; step < 200; ++step) {
        const bool now = down_at(a, 1.7f, 0.3f, SampleSlot{11, step, 4}).t_hit < 1.25f;
        changes += now != last;
        last = now;
    }
    EXPECT_GT(changes, 40u); // 2 * 0.3 * 0.7 * 199 = 84 expected
    // Single-sided (the scene's default): rays from behind pass the blended quad's back face, as in the
    // classical traversal; double-sided: a fraction alpha of them stops there too.
    Scene two_sided = scene;
    two_sided.materials[1].double_sided = true;
    const TrainingAsset b = make_training_asset(two_sided, 0);
    uint32_t from_behind = 0, from_behind_two_sided = 0;
    for (uint32_t slot = 0; slot < 2000; ++slot) {
        const SampleSlot key{13, 0, slot};
        from_behind += trace_ground_truth(a, {1.7f, 0.3f, -0.25f}, {0, 0, 1}, 0.0f, 1.25f, key).hit;
        from_behind_two_sided += trace_ground_truth(b, {1.7f, 0.3f, -0.25f}, {0, 0, 1}, 0.0f, 1.25f, key).hit;
    }
    EXPECT_EQ(from_behind, 0u);
    EXPECT_EQ(from_behind_two_sided, 2000u);
    EXPECT_NEAR(trace_ground_truth(b, {1.7f, 0.3f, -0.25f}, {0, 0, 1}, 0.0f, 1.25f, SampleSlot{}).visibility, 0.3f, 1e-6f);
}

// The visibility target is the probability that the segment stops the ray, not the draw: alpha for the
// blended quad alone, 1 with the opaque backdrop behind it in the segment, 1 - 0.7^2 for two blended
// layers; the surface is the draw's, or the nearest blended crossing when the draws let the ray through.
TEST(AlphaCoverage, VisibilityTargetIsTheStopProbability) {
    Scene scene = test::alpha_quads_scene();
    const TrainingAsset a = make_training_asset(scene, 0);
    for (uint32_t slot = 0; slot < 64; ++slot) {
        const SampleSlot key{17, 2, slot};
        const GroundTruth front = trace_ground_truth(a, {1.7f, 0.3f, 1.0f}, {0, 0, -1}, 0.0f, 1.25f, key);
        ASSERT_TRUE(front.hit);
        EXPECT_NEAR(front.visibility, 0.3f, 1e-6f);
        EXPECT_NEAR(front.t_hit, 1.0f, 1e-6f); // drawn or not, the quad is the only surface
        EXPECT_EQ(trace_ground_truth(a, {1.7f, 0.3f, 1.0f}, {0, 0, -1}, 0.0f, 2.0f, key).visibility, 1.0f);
        // Opaque and MASK-kept surfaces: 1; a MASK hole: what lies behind.
        EXPECT_EQ(trace_ground_truth(a, {0.75f, 0.5f, 1.0f}, {0, 0, -1}, 0.0f, 1.25f, key).visibility, 1.0f);
        EXPECT_FALSE(trace_ground_truth(a, {0.25f, 0.5f, 1.0f}, {0, 0, -1}, 0.0f, 1.25f, key).hit);
    }
    // Two blended layers: the backdrop made blended too (alpha 0.3, no texture).
    scene.materials[2] = scene.materials[1];
    const TrainingAsset two = make_training_asset(scene, 0);
    EXPECT_NEAR(trace_ground_truth(two, {1.7f, 0.3f, 1.0f}, {0, 0, -1}, 0.0f, 2.0f, SampleSlot{}).visibility,
                1.0f - 0.7f * 0.7f, 1e-6f);
}
