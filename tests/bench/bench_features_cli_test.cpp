// nbvh bench-features on lavapipe (the executable as a subprocess): per scene the own and all-forced
// frame times, a row per forcible feature (its time forced alone where the scene lacks it, "in_scene"
// where it has it), identical own and all-forced images (FLIP 0 beside a positive noise floor), device,
// commit and command line in the JSON, the markdown table; user errors are one clean line.
#include <cmath>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/cli/run_nbvh.h"
#include "tests/support/test_support.h"

namespace {
namespace fs = std::filesystem;
using nbvh::test::check_clean_error;
using nbvh::test::run_nbvh;

const char* const FORCIBLE[] = {"textures", "normal_maps", "emission",  "environment",
                                "alpha_mask", "transmission", "punctual", "single_sided"};

std::vector<std::string> tiny(std::vector<std::string> scenes, const fs::path& json, const fs::path& md) {
    std::vector<std::string> a = {"bench-features"};
    a.insert(a.end(), scenes.begin(), scenes.end());
    a.insert(a.end(), {"--device", "cpu", "--width", "32", "--height", "24", "--spp", "1", "--max-depth", "3",
                       "--repeat", "2", "--json", json.string(), "--markdown", md.string()});
    return a;
}

std::string read_text(const fs::path& p) {
    std::ifstream f(p);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

TEST(BenchFeatures, OwnAndForcedOnLavapipe) {
    NBVH_REQUIRE_SHARED();
    const fs::path dir = nbvh::test::temp_dir("bench_features");
    const fs::path bunny = nbvh::test::scenes_dir() / "stanford_bunny" / "stanford_bunny.glb";
    setenv("NBVH_VALIDATION", "1", 1); // the child runs with the validation layer; any message fails
    const auto r = run_nbvh(tiny({"default", bunny.string()}, dir / "f.json", dir / "f.md"), 240.0);
    unsetenv("NBVH_VALIDATION");
    ASSERT_EQ(r.exit_code, 0) << r.describe();
    EXPECT_EQ(r.err.find("vulkan validation"), std::string::npos) << r.err;
    const nlohmann::json j = nlohmann::json::parse(read_text(dir / "f.json"));
    EXPECT_FALSE(j["device"].get<std::string>().empty());
    EXPECT_FALSE(j["commit"].get<std::string>().empty());
    EXPECT_NE(j["command_line"].get<std::string>().find("bench-features default"), std::string::npos);
    ASSERT_EQ(j["scenes"].size(), 2u);
    for (const nlohmann::json& s : j["scenes"]) {
        SCOPED_TRACE(s["scene"].get<std::string>());
        EXPECT_GT(s["own_ms"].get<double>(), 0.0);
        EXPECT_GT(s["all_forced_ms"].get<double>(), 0.0);
        EXPECT_DOUBLE_EQ(s["saved_ms"].get<double>(), s["all_forced_ms"].get<double>() - s["own_ms"].get<double>());
        EXPECT_EQ(s["frames_gpu_ms"]["own"].size(), 2u) << "--repeat 2";
        // Shared random numbers, same paths: the forced image is the own one.
        EXPECT_TRUE(s["images"]["agree"].get<bool>());
        EXPECT_LT(s["images"]["flip_own_vs_all_forced"].get<double>(), 1e-3);
        EXPECT_GT(s["images"]["noise_floor"].get<double>(), 0.0);
        ASSERT_EQ(s["per_feature"].size(), std::size(FORCIBLE));
        for (size_t i = 0; i < std::size(FORCIBLE); ++i) {
            const nlohmann::json& f = s["per_feature"][i];
            EXPECT_EQ(f["feature"], FORCIBLE[i]);
            const bool used = f["in_scene"].get<bool>();
            EXPECT_EQ(used, s["features"].get<std::string>().find(FORCIBLE[i]) != std::string::npos) << FORCIBLE[i];
            EXPECT_EQ(f.contains("forced_ms"), !used) << FORCIBLE[i] << ": timed alone only where the scene lacks it";
            if (!used) { EXPECT_EQ(f["pixels_differing"].get<double>(), 0.0) << FORCIBLE[i]; }
        }
    }
    // The default scene: textures, emission, sky and single-sided materials; the bunny: the sky only.
    EXPECT_EQ(j["scenes"][0]["features"], "textures, emission, environment, single_sided");
    EXPECT_EQ(j["scenes"][1]["features"], "environment");
    const std::string md = read_text(dir / "f.md");
    EXPECT_NE(md.find("| scene | its features | own ms | all forced ms | saved |"), std::string::npos) << md;
    EXPECT_NE(md.find("| default |"), std::string::npos) << md;
    EXPECT_NE(md.find("| stanford_bunny |"), std::string::npos) << md;
}

TEST(BenchFeatures, UserErrorsAreOneLine) {
    const fs::path dir = nbvh::test::temp_dir("bench_features_errors");
    const auto missing = run_nbvh(tiny({(dir / "nope.glb").string()}, dir / "a.json", dir / "a.md"), 60.0);
    EXPECT_EQ(check_clean_error(missing, {"nope.glb"}, false), "") << missing.describe();
    const auto same = run_nbvh(tiny({"default"}, dir / "b.out", dir / "b.out"), 60.0);
    EXPECT_EQ(check_clean_error(same, {"--json", "--markdown"}), "") << same.describe();
    auto zero = tiny({"default"}, dir / "c.json", dir / "c.md");
    zero.insert(zero.end(), {"--repeat", "0"});
    EXPECT_EQ(check_clean_error(run_nbvh(zero, 60.0), {"--repeat"}), "");
    const auto none = run_nbvh({"bench-features", "--device", "cpu"}, 60.0);
    EXPECT_EQ(check_clean_error(none, {"scenes"}), "") << none.describe();
    EXPECT_FALSE(fs::exists(dir / "a.json") || fs::exists(dir / "b.out") || fs::exists(dir / "c.json"));
}

} // namespace
