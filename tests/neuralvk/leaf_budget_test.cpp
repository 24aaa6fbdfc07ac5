// Leaf budgets on lavapipe (the bunny of trained_bunny.h, bunny_render.h): the leaf-cap counter, the
// budgets of rays after the first hit (--neural-max-leaves-secondary) and of shadow rays
// (--neural-max-leaves-shadow), and what a truncated shadow ray does (--neural-truncated-shadows).
#include "engine/core/flip.h"
#include "tests/neuralvk/bunny_render.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <cstdio>

using namespace nbvh;
using namespace nbvh::render;
using namespace nbvh::test;

namespace {

// Two renders that queried the same leaves and counted the same rays at their budget (the batched
// rounds and the tail pass taking the same decisions, or two renders whose paths are the same).
void expect_same_rays(const Rendered& a, const Rendered& b, const char* what) {
    EXPECT_EQ(a.stats.neural_queries, b.stats.neural_queries) << what;
    EXPECT_EQ(a.stats.neural_leaf_cap_rays, b.stats.neural_leaf_cap_rays) << what;
}

// ... and the same image to the bit.
void expect_same_render(const Rendered& a, const Rendered& b, const char* what) {
    EXPECT_EQ(a.image.data, b.image.data) << what;
    expect_same_rays(a, b, what);
}

} // namespace

// The leaf-cap counter (RenderStats::neural_leaf_cap_rays) counts rays that spend their leaf budget (the
// budget may cut them): with one leaf per ray every ray that queries a leaf; the same rays whether the
// batched rounds or the tail pass query it; with a budget no ray reaches, none.
TEST(HybridRender, LeafCapCounterCountsRaysAtTheirBudget) {
    NBVH_REQUIRE_SHARED();
    const Fixture& f = trained_bunny();
    const Rendered cap1 = render_bunny(f, true, rounds(256, 1, 1));
    const Rendered cap1_tail = render_bunny(f, true, rounds(0, 1, 1));
    const Rendered cap256 = render_bunny(f, true, rounds(256, 4, 256));
    EXPECT_EQ(cap1.validation + cap1_tail.validation + cap256.validation, 0);
    std::printf("leaf-cap rays: budget 1: %llu (tail: %llu), budget 256: %llu of %llu rays\n",
                (unsigned long long)cap1.stats.neural_leaf_cap_rays,
                (unsigned long long)cap1_tail.stats.neural_leaf_cap_rays,
                (unsigned long long)cap256.stats.neural_leaf_cap_rays,
                (unsigned long long)cap256.stats.rays_total());
    EXPECT_GT(cap1.stats.neural_leaf_cap_rays, 0u);
    expect_same_rays(cap1, cap1_tail, "budget 1: batched vs tail");
    EXPECT_EQ(cap256.stats.neural_leaf_cap_rays, 0u);
    EXPECT_LT(cap1.stats.neural_leaf_cap_rays, cap1.stats.rays_total());
}

// Truncated shadow rays (--neural-truncated-shadows): blocking them only takes light away (no pixel
// brighter, the mean darker) and changes no path (same queries, same rays counted at their budget). The
// decision needs the leaf beyond the budget: found by the round that spends it (one leaf more looked
// for), by the resumed traversal where a round of 4 leaves leaves no room, or by the tail pass: the same
// decisions, so the same image.
TEST(HybridRender, TruncatedShadowsPassOrBlock) {
    NBVH_REQUIRE_SHARED();
    const Fixture& f = trained_bunny();
    auto truncate = [](uint32_t batched, uint32_t per_round, uint32_t secondary, float occlusion) {
        return [=](RenderOptions& o) {
            rounds(batched, per_round, 8)(o);
            o.neural.max_rounds_secondary = secondary;
            o.neural.truncated_shadows_occlusion = occlusion;
        };
    };
    const Rendered pass = render_bunny(f, true, truncate(256, 1, 1, 0.0f));
    const Rendered block = render_bunny(f, true, truncate(256, 1, 1, 1.0f));
    const Rendered block_tail = render_bunny(f, true, truncate(0, 1, 1, 1.0f));
    const Rendered half = render_bunny(f, true, truncate(256, 1, 1, 0.5f)); // some truncated rays occluded
    const Rendered half_tail = render_bunny(f, true, truncate(0, 1, 1, 0.5f));
    const Rendered block2 = render_bunny(f, true, truncate(256, 2, 4, 1.0f)); // looks one leaf further
    const Rendered block4 = render_bunny(f, true, truncate(256, 4, 4, 1.0f)); // resumed once more
    const Rendered pass4 = render_bunny(f, true, truncate(256, 4, 4, 0.0f));
    EXPECT_EQ(pass.validation + block.validation + block_tail.validation + block2.validation +
                  block4.validation + pass4.validation,
              0);
    const float f_tail = flip_hdr(block.image, block_tail.image).mean;
    const float f_room = flip_hdr(block2.image, block4.image).mean;
    std::printf(
        "truncated shadow rays: image mean pass %.5f, block %.5f; rays at their budget %llu / %llu; FLIP "
        "block vs its tail %.2e, 2 vs 4 leaves per round %.2e\n",
        image_mean(pass.image), image_mean(block.image), (unsigned long long)pass.stats.neural_leaf_cap_rays,
        (unsigned long long)block.stats.neural_leaf_cap_rays, f_tail, f_room);
    ASSERT_EQ(block.image.data.size(), pass.image.data.size());
    size_t brighter = 0;
    for (size_t k = 0; k < pass.image.data.size(); ++k)
        brighter += block.image.data[k] > pass.image.data[k] * (1.0f + 1e-5f) + 1e-6f ? 1u : 0u;
    EXPECT_EQ(brighter, 0u);
    EXPECT_LT(image_mean(block.image), image_mean(pass.image));
    expect_same_rays(block, pass, "block vs pass");
    EXPECT_GT(block.stats.neural_leaf_cap_rays, 0u);
    EXPECT_EQ(block.stats.nonfinite_pixels, 0u);
    EXPECT_EQ(block_tail.stats.neural_leaf_cap_rays, block.stats.neural_leaf_cap_rays);
    EXPECT_LT(f_tail, 1e-3f);
    EXPECT_LT(f_room, 1e-3f);
    // Occluded with probability 1/2 (the same paths): between the two in every pixel, strictly in the
    // mean; the tail pass draws the same decisions.
    std::printf("occluded with probability 0.5: image mean %.5f, FLIP vs its tail %.2e\n",
                image_mean(half.image), flip_hdr(half.image, half_tail.image).mean);
    EXPECT_EQ(half.validation + half_tail.validation, 0);
    EXPECT_EQ(half.stats.neural_queries, pass.stats.neural_queries);
    size_t outside = 0;
    for (size_t k = 0; k < pass.image.data.size(); ++k)
        outside += half.image.data[k] > pass.image.data[k] * (1.0f + 1e-5f) + 1e-6f ||
                           half.image.data[k] < block.image.data[k] * (1.0f - 1e-5f) - 1e-6f
                       ? 1u
                       : 0u;
    EXPECT_EQ(outside, 0u);
    EXPECT_LT(image_mean(half.image), image_mean(pass.image));
    EXPECT_GT(image_mean(half.image), image_mean(block.image));
    EXPECT_LT(flip_hdr(half.image, half_tail.image).mean, 1e-3f);
    // The resumed traversal (4 leaves per round) blocks some shadow rays too: the comparison above is
    // not between two images without a blocked ray.
    std::printf("budget 4, 4 leaves per round: image mean pass %.5f, block %.5f\n", image_mean(pass4.image),
                image_mean(block4.image));
    EXPECT_LT(image_mean(block4.image), image_mean(pass4.image));
}

// The secondary leaf budget (--neural-max-leaves-secondary) truncates rays after the first hit and shadow
// rays only: the camera rays' budget (0) or its value gives the same image; budget 1 for them queries less
// than the default and more than budget 1 for every ray, truncates fewer rays than the latter, and the tail
// pass (which keeps the budgets per ray) takes the same decisions as the batched rounds.
TEST(HybridRender, SecondaryLeafBudgetTruncatesLaterRaysOnly) {
    NBVH_REQUIRE_SHARED();
    const Fixture& f = trained_bunny();
    auto secondary = [](uint32_t batched, uint32_t budget) {
        return [=](RenderOptions& o) {
            rounds(batched, 1, 8)(o);
            o.neural.max_rounds_secondary = budget;
        };
    };
    const Rendered base = render_bunny(f, true, secondary(256, 0));
    const Rendered same = render_bunny(f, true, secondary(256, 8));
    const Rendered sec1 = render_bunny(f, true, secondary(256, 1));
    const Rendered sec1_tail = render_bunny(f, true, secondary(0, 1));
    const Rendered all1 = render_bunny(f, true, rounds(256, 1, 1)); // the secondary budget then 1 too
    const Rendered sec4 = render_bunny(f, true, secondary(256, 4)); // the default secondary budget before 2
    EXPECT_EQ(base.validation + same.validation + sec1.validation + sec1_tail.validation + all1.validation +
                  sec4.validation,
              0);
    std::printf("secondary budget: queries %llu (8) / %llu (secondary 1) / %llu (all 1); truncated rays %llu "
                "/ %llu / %llu\n",
                (unsigned long long)base.stats.neural_queries, (unsigned long long)sec1.stats.neural_queries,
                (unsigned long long)all1.stats.neural_queries,
                (unsigned long long)base.stats.neural_leaf_cap_rays,
                (unsigned long long)sec1.stats.neural_leaf_cap_rays,
                (unsigned long long)all1.stats.neural_leaf_cap_rays);
    expect_same_render(same, base, "secondary budget 8 vs 0");
    EXPECT_LT(sec1.stats.neural_queries, base.stats.neural_queries);
    EXPECT_GT(sec1.stats.neural_queries, all1.stats.neural_queries);
    EXPECT_GT(sec1.stats.neural_leaf_cap_rays, base.stats.neural_leaf_cap_rays);
    EXPECT_LT(sec1.stats.neural_leaf_cap_rays, all1.stats.neural_leaf_cap_rays);
    expect_same_rays(sec1_tail, sec1, "secondary 1: tail vs batched");
    EXPECT_EQ(sec1.stats.nonfinite_pixels, 0u);
    EXPECT_LE(sec4.stats.neural_queries, base.stats.neural_queries);
    EXPECT_GT(sec4.stats.neural_queries, sec1.stats.neural_queries);
}

// The shadow rays' own budget (--neural-max-leaves-shadow): its value equal to the path rays' budget is
// the default (same image); a larger one queries more and truncates fewer rays, and where it leaves no
// shadow ray truncated, blocking or passing the truncated ones gives the same image (the decision takes
// the shadow budget, not the path rays'), while at shadow budget 1 blocking darkens it. The tail pass
// keeps the three budgets apart (same decisions as the batched rounds).
TEST(HybridRender, ShadowLeafBudgetIsTheShadowRaysOwn) {
    NBVH_REQUIRE_SHARED();
    const Fixture& f = trained_bunny();
    auto budgets = [](uint32_t batched, uint32_t path, uint32_t shadow, bool block) {
        return [=](RenderOptions& o) {
            rounds(batched, 1, 8)(o);
            o.neural.max_rounds_secondary = path;
            o.neural.max_rounds_shadow = shadow;
            o.neural.truncated_shadows_occlusion = block ? 1.0f : 0.0f;
        };
    };
    const Rendered p1 = render_bunny(f, true, budgets(256, 1, 0, false));
    const Rendered p1s1 = render_bunny(f, true, budgets(256, 1, 1, false));
    const Rendered p1s8 = render_bunny(f, true, budgets(256, 1, 8, false));
    const Rendered p1s8_block = render_bunny(f, true, budgets(256, 1, 8, true));
    const Rendered p1s8_tail = render_bunny(f, true, budgets(0, 1, 8, false));
    const Rendered p8s1 = render_bunny(f, true, budgets(256, 8, 1, false));
    const Rendered p8s1_block = render_bunny(f, true, budgets(256, 8, 1, true));
    EXPECT_EQ(p1.validation + p1s1.validation + p1s8.validation + p1s8_block.validation +
                  p1s8_tail.validation + p8s1.validation + p8s1_block.validation,
              0);
    std::printf("shadow budget (path budget 1): queries %llu (shadow 1) / %llu (shadow 8), truncated %llu / "
                "%llu; path 8 shadow 1: image mean pass %.5f, block %.5f\n",
                (unsigned long long)p1.stats.neural_queries, (unsigned long long)p1s8.stats.neural_queries,
                (unsigned long long)p1.stats.neural_leaf_cap_rays,
                (unsigned long long)p1s8.stats.neural_leaf_cap_rays, image_mean(p8s1.image),
                image_mean(p8s1_block.image));
    expect_same_render(p1s1, p1, "shadow budget 1 vs the path rays' 1");
    EXPECT_GT(p1s8.stats.neural_queries, p1.stats.neural_queries);
    EXPECT_LT(p1s8.stats.neural_leaf_cap_rays, p1.stats.neural_leaf_cap_rays);
    EXPECT_EQ(p1s8_block.image.data, p1s8.image.data);
    expect_same_rays(p1s8_tail, p1s8, "path 1 shadow 8: tail vs batched");
    EXPECT_LT(image_mean(p8s1_block.image), image_mean(p8s1.image));
    EXPECT_EQ(p8s1.stats.nonfinite_pixels + p1s8.stats.nonfinite_pixels, 0u);
}
