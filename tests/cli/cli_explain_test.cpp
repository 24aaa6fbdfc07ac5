// `nbvh render --explain` prints the render it would run (issue 12, label lavapipe): for a hybrid render
// (--model) the neural stage built as the renderer builds it on the device (MLP path, LoD, leaves per
// round) and the neural passes; without a model or with --classical, the classical passes only.
#include <gtest/gtest.h>

#include "tests/cli/run_nbvh.h"
#include "tests/support/test_support.h"

namespace {
namespace fs = std::filesystem;
using nbvh::test::check_clean_error;
using nbvh::test::run_nbvh;

const fs::path& tiny_model() { return nbvh::test::tiny_default_model("cli_explain_model"); }

std::vector<std::string> explain(std::vector<std::string> extra) {
    std::vector<std::string> a = {"render", "default", "--device", "cpu", "--explain"};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
}

bool has(const std::string& text, const std::string& word) { return text.find(word) != std::string::npos; }

TEST(CliExplain, HybridRenderListsTheNeuralPasses) {
    const auto r =
        run_nbvh(explain({"--model", tiny_model().string(), "--lod", "1", "--secondary-lod", "0"}), 60.0);
    ASSERT_EQ(r.exit_code, 0) << r.describe();
    const std::string& o = r.out;
    EXPECT_TRUE(has(o, "neural assets   yes")) << o;
    // lavapipe has no cooperative matrices: auto picks the scalar path, as the renderer would.
    EXPECT_TRUE(has(o, "MLP path        scalar")) << o;
    EXPECT_TRUE(has(o, "camera rays 1, after the first hit 0 (the model has 2")) << o;
    // the defaults
    EXPECT_TRUE(has(o, "at most 8 (rays after the first hit 2, shadow rays 2), 1 queued per round (the "
                       "others 2): 8 batched rounds (the others 1, shadow rays 1)"))
        << o;
    EXPECT_TRUE(has(o, "truncated rays  a shadow ray is occluded")) << o;
    EXPECT_TRUE(has(o, "occupancy masks on")) << o;
    EXPECT_TRUE(has(o, "back-face escape on")) << o;
    EXPECT_TRUE(has(o, "materials       per node")) << o;
    for (const char* pass :
         {"passes/neural_traverse.comp", "passes/neural_args.comp", "passes/neural_query_scalar.comp",
          "passes/neural_tail.comp", "passes/neural_shadow.comp", "passes/shade.comp"})
        EXPECT_TRUE(has(o, pass)) << pass << "\n" << o;
    EXPECT_FALSE(has(o, "passes/traverse.comp")) << "hybrid renders traverse through the neural rounds\n"
                                                 << o;
}

TEST(CliExplain, SecondaryRaysTakeTheCoarsestLodByDefault) {
    // Default --secondary-lod coarsest: the model's coarsest cut after the first hit (issue 14; the study's
    // "LoD 0, then 2 after the first hit" rows), never finer than --lod; 'same' and an index as asked.
    struct Case {
        std::vector<std::string> flags;
        const char* expect;
    };
    const Case cases[] = {{{}, "camera rays 0, after the first hit 1 (the model has 2"},
                          {{"--lod", "1"}, "camera rays 1, after the first hit 1 (the model has 2"},
                          {{"--secondary-lod", "same"}, "camera rays 0, after the first hit 0 (the model has 2"},
                          {{"--secondary-lod", "coarsest"}, "camera rays 0, after the first hit 1 (the model has 2"},
                          {{"--lod", "1", "--secondary-lod", "0"}, "camera rays 1, after the first hit 0 (the model"}};
    for (const Case& c : cases) {
        std::vector<std::string> flags = {"--model", tiny_model().string()};
        flags.insert(flags.end(), c.flags.begin(), c.flags.end());
        const auto r = run_nbvh(explain(flags), 60.0);
        ASSERT_EQ(r.exit_code, 0) << r.describe();
        EXPECT_TRUE(has(r.out, c.expect)) << c.expect << "\n" << r.out;
    }
    for (const char* bad : {"finest", "-1", "8", "2"}) { // 2: the model has LoDs 0..1
        const auto r = run_nbvh(explain({"--model", tiny_model().string(), "--secondary-lod", bad}), 60.0);
        EXPECT_EQ(check_clean_error(r, {"--secondary-lod"}, false), "") << bad << "\n" << r.describe();
    }
}

TEST(CliExplain, LeavesPerRoundComeFromTheRenderersStage) {
    // --neural-leaves-per-round reaches the renderer's stage (it was a hidden environment variable).
    const auto r = run_nbvh(explain({"--model", tiny_model().string(), "--neural-leaves-per-round", "3"}), 60.0);
    ASSERT_EQ(r.exit_code, 0) << r.describe();
    EXPECT_TRUE(has(r.out, "at most 8 (rays after the first hit 2, shadow rays 2), 1 queued per round (the "
                           "others 3): 8 batched rounds (the others 1, shadow rays 1)"))
        << r.out;
    // --neural-leaves-per-round-camera: the camera rays' rounds.
    const auto c =
        run_nbvh(explain({"--model", tiny_model().string(), "--neural-leaves-per-round-camera", "3"}), 60.0);
    ASSERT_EQ(c.exit_code, 0) << c.describe();
    EXPECT_TRUE(has(c.out, "at most 8 (rays after the first hit 2, shadow rays 2), 3 queued per round (the "
                           "others 2): 3 batched rounds (the others 1, shadow rays 1)"))
        << c.out;
    for (const char* bad : {"0", "5"}) {
        const auto e = run_nbvh(
            explain({"--model", tiny_model().string(), "--neural-leaves-per-round-camera", bad}), 60.0);
        EXPECT_EQ(check_clean_error(e, {"--neural-leaves-per-round-camera"}, false), "") << bad << "\n"
                                                                                         << e.describe();
    }
    // The secondary leaf budget, never above the camera rays'.
    const auto s = run_nbvh(explain({"--model", tiny_model().string(), "--neural-max-leaves", "3",
                                     "--neural-max-leaves-secondary", "6"}),
                            60.0);
    ASSERT_EQ(s.exit_code, 0) << s.describe();
    EXPECT_TRUE(has(s.out, "at most 3 (rays after the first hit 3, shadow rays 3)")) << s.out;
    const auto bad_secondary =
        run_nbvh(explain({"--model", tiny_model().string(), "--neural-max-leaves-secondary", "300"}), 60.0);
    EXPECT_EQ(check_clean_error(bad_secondary, {"--neural-max-leaves-secondary"}, false), "")
        << bad_secondary.describe();
    // The shadow rays' own budget: apart from the path rays', never above the camera rays', its rounds.
    const auto sh = run_nbvh(explain({"--model", tiny_model().string(), "--neural-max-leaves-secondary", "1",
                                      "--neural-max-leaves-shadow", "5"}),
                             60.0);
    ASSERT_EQ(sh.exit_code, 0) << sh.describe();
    EXPECT_TRUE(has(sh.out, "at most 8 (rays after the first hit 1, shadow rays 5), 1 queued per round (the "
                            "others 2): 8 batched rounds (the others 1, shadow rays 3)"))
        << sh.out;
    // ... and the pass list's rounds of each kind (the shadow rays' 3, not the path rays' 1).
    EXPECT_TRUE(has(sh.out, "repeat 8 x (batched rounds; 1 after the first hit):")) << sh.out;
    EXPECT_TRUE(has(sh.out, "repeat 3 x (batched rounds):\n")) << sh.out;
    const auto sh_cap = run_nbvh(explain({"--model", tiny_model().string(), "--neural-max-leaves", "3",
                                          "--neural-max-leaves-shadow", "6"}),
                                 60.0);
    ASSERT_EQ(sh_cap.exit_code, 0) << sh_cap.describe();
    EXPECT_TRUE(has(sh_cap.out, "at most 3 (rays after the first hit 2, shadow rays 3)")) << sh_cap.out;
    for (const char* bad : {"300", "-1", "x"}) {
        const auto e =
            run_nbvh(explain({"--model", tiny_model().string(), "--neural-max-leaves-shadow", bad}), 60.0);
        EXPECT_EQ(check_clean_error(e, {"--neural-max-leaves-shadow"}, false), "") << bad << "\n" << e.describe();
    }
    // What a truncated shadow ray does, either way and a bad value.
    const auto block =
        run_nbvh(explain({"--model", tiny_model().string(), "--neural-truncated-shadows", "block"}), 60.0);
    ASSERT_EQ(block.exit_code, 0) << block.describe();
    EXPECT_TRUE(has(block.out, "truncated rays  a shadow ray is occluded")) << block.out;
    const auto pass =
        run_nbvh(explain({"--model", tiny_model().string(), "--neural-truncated-shadows", "pass"}), 60.0);
    ASSERT_EQ(pass.exit_code, 0) << pass.describe();
    EXPECT_TRUE(has(pass.out, "truncated rays  keep their closest hit, a shadow ray is unoccluded"))
        << pass.out;
    const auto quarter =
        run_nbvh(explain({"--model", tiny_model().string(), "--neural-truncated-shadows", "0.25"}), 60.0);
    ASSERT_EQ(quarter.exit_code, 0) << quarter.describe();
    EXPECT_TRUE(has(quarter.out, "leaves out with probability 0.25")) << quarter.out;
    for (const char* v : {"maybe", "1.5", "-0.1", "nan", "0.5x", ""}) {
        const auto bad_shadows =
            run_nbvh(explain({"--model", tiny_model().string(), "--neural-truncated-shadows", v}), 60.0);
        EXPECT_EQ(check_clean_error(bad_shadows, {"--neural-truncated-shadows"}, false), "")
            << v << "\n" << bad_shadows.describe();
    }
    const auto bad = run_nbvh(explain({"--model", tiny_model().string(), "--neural-leaves-per-round", "9"}), 60.0);
    EXPECT_EQ(check_clean_error(bad, {"--neural-leaves-per-round"}, false), "") << bad.describe();
}

TEST(CliExplain, ClassicalRendersHaveNoNeuralPasses) {
    for (const auto& extra : {std::vector<std::string>{},
                              std::vector<std::string>{"--model", tiny_model().string(), "--classical"}}) {
        const auto r = run_nbvh(explain(extra), 60.0);
        ASSERT_EQ(r.exit_code, 0) << r.describe();
        EXPECT_TRUE(has(r.out, "neural assets   no")) << r.out;
        EXPECT_TRUE(has(r.out, "passes/traverse.comp")) << r.out;
        EXPECT_FALSE(has(r.out, "neural_")) << r.out;
    }
}

TEST(CliExplain, ForcedCoopmatOnLavapipeIsTheRendersError) {
    const auto r = run_nbvh(explain({"--model", tiny_model().string(), "--neural-path", "coopmat"}), 60.0);
    EXPECT_EQ(check_clean_error(r, {"coopmat"}, false), "") << r.describe();
}

} // namespace

// A model of `nbvh train` (format 5) has node means and fits: fits and their spread by default, the fit
// alone or the means on request.
TEST(CliExplain, MaterialModesAreNamed) {
    const auto mix = run_nbvh(explain({"--model", tiny_model().string()}), 60.0);
    ASSERT_EQ(mix.exit_code, 0) << mix.describe();
    EXPECT_TRUE(has(mix.out, "materials       per node, fit + spread (")) << mix.out;
    const auto fit = run_nbvh(explain({"--model", tiny_model().string(), "--neural-materials", "fit"}), 60.0);
    ASSERT_EQ(fit.exit_code, 0) << fit.describe();
    EXPECT_TRUE(has(fit.out, "materials       per node, fit (--neural-materials fit")) << fit.out;
    const auto node = run_nbvh(explain({"--model", tiny_model().string(), "--neural-materials", "node"}), 60.0);
    ASSERT_EQ(node.exit_code, 0) << node.describe();
    EXPECT_TRUE(has(node.out, "materials       per node, mean (--neural-materials node)")) << node.out;
}

TEST(CliExplain, CullingSwitchesAreNamed) {
    const auto r = run_nbvh(explain({"--model", tiny_model().string(), "--neural-occupancy", "off",
                                     "--neural-backface-escape", "off", "--neural-materials", "asset"}),
                            60.0);
    ASSERT_EQ(r.exit_code, 0) << r.describe();
    EXPECT_TRUE(has(r.out, "occupancy masks off (--neural-occupancy off)")) << r.out;
    EXPECT_TRUE(has(r.out, "back-face escape off (--neural-backface-escape off)")) << r.out;
    EXPECT_TRUE(has(r.out, "materials       per asset (--neural-materials asset)")) << r.out;
    const auto bad = run_nbvh(explain({"--model", tiny_model().string(), "--neural-backface-escape", "maybe"}), 60.0);
    EXPECT_EQ(check_clean_error(bad, {"--neural-backface-escape"}, false), "") << bad.describe();
    const auto bad2 = run_nbvh(explain({"--model", tiny_model().string(), "--neural-materials", "leaf"}), 60.0);
    EXPECT_EQ(check_clean_error(bad2, {"--neural-materials"}, false), "") << bad2.describe();
}
