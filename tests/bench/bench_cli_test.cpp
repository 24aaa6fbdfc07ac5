// nbvh bench on lavapipe: one row per level of detail with positive GPU times and a finite FLIP in
// [0,1] against the classical reference; user errors (missing model, wrong asset) are one clean line.
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

// A tiny 2-LoD model of the default scene (a few seconds on the CPU backend), trained once.
const fs::path& tiny_model() {
    static const fs::path model = [] {
        const fs::path dir = nbvh::test::temp_dir("bench_model");
        const fs::path m = dir / "tiny.nbvh";
        const auto r = run_nbvh({"train", "default", "--backend", "cpu", "--steps", "20", "--batch", "256", "--nodes",
                                 "63", "--hash-log2", "12", "--lods", "2", "--threads", "2", "--out", m.string()},
                                120.0);
        EXPECT_EQ(r.exit_code, 0) << r.describe();
        return m;
    }();
    return model;
}

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
    EXPECT_GT(j["classical"]["gpu_ms"].get<double>(), 0.0);
    const auto& rows = j["lods"];
    ASSERT_EQ(rows.size(), 2u) << j.dump(2); // --lods 2
    for (size_t i = 0; i < rows.size(); ++i) {
        const auto& row = rows[i];
        EXPECT_EQ(row["lod"].get<uint32_t>(), i);
        EXPECT_GT(row["nodes"].get<uint32_t>(), 0u);
        EXPECT_GT(row["neural_bytes"].get<uint64_t>(), 0u);
        EXPECT_GT(row["gpu_ms"].get<double>(), 0.0);
        EXPECT_GT(row["ratio_to_classical"].get<double>(), 0.0);
        EXPECT_GT(row["neural_queries"].get<uint64_t>(), 0u); // the camera sees the neural asset
        const double flip = row["flip"].get<double>();
        EXPECT_TRUE(std::isfinite(flip) && flip >= 0.0 && flip <= 1.0) << flip;
    }
    // Coarser cuts have fewer nodes.
    EXPECT_LT(rows[1]["nodes"].get<uint32_t>(), rows[0]["nodes"].get<uint32_t>());
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
