// nbvh bench on lavapipe: one row per level of detail with positive GPU times and a finite FLIP in
// [0,1] against the classical reference, the noise floor beside it, commit and command line in the JSON;
// any scene (a glTF file without "*_neural" nodes, its model trained with --neural); user errors
// (missing model, wrong asset) are one clean line.
#include <cmath>
#include <cstdlib>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/cli/run_nbvh.h"
#include "tests/support/test_support.h"

namespace {
namespace fs = std::filesystem;
using nbvh::test::check_clean_error;
using nbvh::test::run_nbvh;

std::vector<std::string> tiny_bench(const fs::path& model, const fs::path& json) {
    return {"bench", "default", "--model", model.string(), "--device", "cpu", "--width", "32", "--height", "32",
            "--spp", "1", "--repeat", "1", "--json", json.string()};
}

const fs::path& tiny_model() { return nbvh::test::tiny_default_model("bench_model"); }

TEST(Bench, TinyModelOnLavapipe) {
    const fs::path json = nbvh::test::temp_dir("bench_run") / "out.json";
    fs::remove(json);
    const fs::path model = tiny_model();
    setenv("NBVH_VALIDATION", "1", 1); // the child runs with the validation layer; any message fails
    const auto r = run_nbvh(tiny_bench(model, json), 120.0);
    unsetenv("NBVH_VALIDATION");
    ASSERT_EQ(r.exit_code, 0) << r.describe();
    EXPECT_EQ(r.err.find("vulkan validation"), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("FLIP"), std::string::npos) << r.out;
    std::ifstream f(json);
    ASSERT_TRUE(f.good());
    const nlohmann::json j = nlohmann::json::parse(f);
    EXPECT_FALSE(j["device"].get<std::string>().empty());
    EXPECT_FALSE(j["commit"].get<std::string>().empty());
    EXPECT_NE(j["command_line"].get<std::string>().find("bench default"), std::string::npos);
    const double floor = j["noise_floor"].get<double>();
    EXPECT_TRUE(std::isfinite(floor) && floor > 0.0 && floor <= 1.0) << floor;
    EXPECT_NE(r.out.find("noise floor"), std::string::npos) << r.out;
    EXPECT_GT(j["classical"]["gpu_ms"].get<double>(), 0.0);
    const auto& rows = j["lods"];
    ASSERT_EQ(rows.size(), 2u) << j.dump(2); // --lods 2
    for (size_t i = 0; i < rows.size(); ++i) {
        const auto& row = rows[i];
        EXPECT_EQ(row["lod"].get<uint32_t>(), i);
        EXPECT_GT(row["nodes"].get<uint32_t>(), 0u);
        EXPECT_GT(row["neural_bytes"].get<uint64_t>(), 0u);
        EXPECT_GE(row["resident_bytes"].get<uint64_t>(), row["neural_bytes"].get<uint64_t>());
        EXPECT_EQ(row["within_2x_floor"].get<bool>(), row["flip"].get<double>() <= 2.0 * floor);
        EXPECT_GT(row["gpu_ms"].get<double>(), 0.0);
        EXPECT_GT(row["ratio_to_classical"].get<double>(), 0.0);
        EXPECT_GT(row["neural_queries"].get<uint64_t>(), 0u); // the camera sees the neural asset
        const double flip = row["flip"].get<double>();
        EXPECT_TRUE(std::isfinite(flip) && flip >= 0.0 && flip <= 1.0) << flip;
    }
    // Coarser cuts have fewer nodes.
    EXPECT_LT(rows[1]["nodes"].get<uint32_t>(), rows[0]["nodes"].get<uint32_t>());
}

// A glTF scene with no "*_neural" node: the model (trained with --neural) decides which instances are neural.
TEST(Bench, AnySceneWithItsModel) {
    NBVH_REQUIRE_SHARED();
    const fs::path scene = nbvh::test::scenes_dir() / "stanford_bunny" / "stanford_bunny.glb";
    const fs::path dir = nbvh::test::temp_dir("bench_bunny");
    const fs::path model = dir / "bunny.nbvh", json = dir / "out.json";
    auto r = run_nbvh({"train", scene.string(), "--neural", "*", "--backend", "cpu", "--steps", "10", "--batch", "256",
                       "--nodes", "15", "--hash-log2", "10", "--threads", "2", "--out", model.string()},
                      120.0);
    ASSERT_EQ(r.exit_code, 0) << r.describe();
    r = run_nbvh({"bench", scene.string(), "--model", model.string(), "--device", "cpu", "--width", "32", "--height",
                  "32", "--spp", "1", "--repeat", "1", "--json", json.string()},
                 120.0);
    ASSERT_EQ(r.exit_code, 0) << r.describe();
    std::ifstream f(json);
    const nlohmann::json j = nlohmann::json::parse(f);
    ASSERT_EQ(j["lods"].size(), 3u) << "nbvh train keeps 3 levels of detail by default";
    for (const auto& row : j["lods"]) EXPECT_GT(row["neural_queries"].get<uint64_t>(), 0u) << "the bunny is neural";
}

TEST(Bench, MissingModelIsOneLine) {
    const fs::path dir = nbvh::test::temp_dir("bench_missing");
    const auto r = run_nbvh(tiny_bench(dir / "nope.nbvh", dir / "o.json"));
    EXPECT_EQ(check_clean_error(r, {"nope.nbvh"}), "") << r.describe();
    EXPECT_FALSE(fs::exists(dir / "o.json"));
}

TEST(Bench, ModelOptionRequired) {
    const auto r = run_nbvh({"bench", "default", "--device", "cpu"});
    EXPECT_EQ(check_clean_error(r, {"--model"}), "") << r.describe();
}

TEST(Bench, JsonIntoMissingDirectoryFailsFirst) {
    const fs::path dir = nbvh::test::temp_dir("bench_json");
    const auto r = run_nbvh(tiny_bench(dir / "nope.nbvh", dir / "no" / "such" / "o.json"));
    EXPECT_EQ(check_clean_error(r, {"--json"}), "") << r.describe();
}

} // namespace
