// `nbvh converge` end to end on lavapipe (issue 11): a tiny CPU-trained model of the default scene, its
// hybrid and classical images extended from 2 to 8 spp against a 32-spp reference; the table, JSON and
// CSV hold one row per doubling with finite FLIPs, the noise taken out in quadrature as documented, and
// the rows of a progressive film equal those of fresh renders at that spp; scripts/bench/plot_convergence.py
// draws them. Bad arguments are one-line errors before anything renders.
#include <cmath>
#include <cstdlib>
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

const fs::path& tiny_model() { return nbvh::test::tiny_default_model("converge_model"); }

std::vector<std::string> converge(const fs::path& dir, const std::string& from, const std::string& spp) {
    return {"converge", "default",   "--model", tiny_model().string(), "--device", "cpu",
            "--width",  "32",        "--height", "18",                 "--from",   from,
            "--spp",    spp,         "--ref-spp", "32",                "--json",   (dir / "c.json").string(),
            "--csv",    (dir / "c.csv").string()};
}

nlohmann::json read_json(const fs::path& p) {
    std::ifstream f(p);
    return nlohmann::json::parse(f);
}

TEST(Converge, DoublingsToTheLargestSppWithFloorAndSharedSeed) {
    const fs::path dir = nbvh::test::temp_dir("converge_table");
    setenv("NBVH_VALIDATION", "1", 1); // any validation message fails the run's check below
    const auto r = run_nbvh(converge(dir, "2", "8"), 300.0);
    unsetenv("NBVH_VALIDATION");
    ASSERT_EQ(r.exit_code, 0) << r.describe();
    EXPECT_EQ(r.err.find("validation messages"), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("noise floor"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("shared seed"), std::string::npos) << r.out;

    const nlohmann::json j = read_json(dir / "c.json");
    for (const char* k : {"device", "driver", "commit", "command_line", "ref_spp", "reference_seed", "exposure_stops"})
        EXPECT_TRUE(j.contains(k)) << k;
    EXPECT_EQ(j["ref_spp"].get<uint32_t>(), 32u);
    EXPECT_EQ(j["sampler"].get<std::string>(), "sobol"); // the default (--sampler)
    EXPECT_NE(j["command_line"].get<std::string>().find("converge"), std::string::npos);
    ASSERT_EQ(j["rows"].size(), 3u);
    const uint32_t spps[] = {2, 4, 8};
    for (size_t i = 0; i < 3; ++i) {
        const nlohmann::json& row = j["rows"][i];
        EXPECT_EQ(row["spp"].get<uint32_t>(), spps[i]);
        const double floor = row["noise_floor"], flip = row["flip"], shared = row["flip_same_seed"],
                     less = row["flip_less_floor"];
        for (double v : {floor, flip, shared, less}) {
            EXPECT_TRUE(std::isfinite(v));
            EXPECT_GE(v, 0.0);
            EXPECT_LE(v, 1.0);
        }
        // 2..8 spp against 32: noise is visible, and a 20-step model differs from its triangles.
        EXPECT_GT(floor, 0.0) << i;
        EXPECT_GT(shared, 0.0) << i;
        EXPECT_NEAR(less, std::sqrt(std::max(0.0, flip * flip - floor * floor)), 1e-6) << i;
        EXPECT_GT(row["hybrid_gpu_ms"].get<double>(), 0.0);
        EXPECT_GT(row["classical_gpu_ms"].get<double>(), 0.0);
    }
    // The CSV carries the same rows.
    std::ifstream csv(dir / "c.csv");
    std::string line;
    std::getline(csv, line);
    EXPECT_EQ(line, "spp,noise_floor,flip,flip_same_seed,flip_less_floor,classical_gpu_ms,hybrid_gpu_ms");
    int rows = 0;
    while (std::getline(csv, line)) {
        std::stringstream ss(line);
        std::string spp;
        std::getline(ss, spp, ',');
        EXPECT_EQ(std::stoul(spp), spps[rows]);
        ++rows;
    }
    EXPECT_EQ(rows, 3);

    // One film extended 2 -> 4 -> 8 holds what a fresh 8-spp render of that seed holds: the same FLIPs.
    const fs::path fresh = nbvh::test::temp_dir("converge_fresh");
    const auto r8 = run_nbvh(converge(fresh, "8", "8"), 300.0);
    ASSERT_EQ(r8.exit_code, 0) << r8.describe();
    const nlohmann::json j8 = read_json(fresh / "c.json");
    ASSERT_EQ(j8["rows"].size(), 1u);
    for (const char* k : {"noise_floor", "flip", "flip_same_seed"})
        EXPECT_EQ(j8["rows"][0][k].get<double>(), j["rows"][2][k].get<double>()) << k;

    // scripts/bench/plot_convergence.py: one panel per scene (both runs in it), a PNG, and the table
    // naming the device.
    const fs::path python = "/usr/bin/python3"; // Debian's, with python3-matplotlib (scripts/setup.sh)
    if (nbvh::test::run_command(python, {"-c", "import matplotlib"}, 60.0).exit_code != 0)
        GTEST_SKIP() << "python3-matplotlib is not installed (scripts/setup.sh installs it): plot not checked";
    const fs::path png = dir / "convergence.png";
    const auto p = nbvh::test::run_command(
        python, {(nbvh::test::source_dir() / "scripts/bench/plot_convergence.py").string(), (dir / "c.json").string(),
                 (fresh / "c.json").string(), png.string()},
        120.0);
    ASSERT_EQ(p.exit_code, 0) << p.describe();
    std::ifstream f(png, std::ios::binary);
    char sig[8] = {};
    f.read(sig, 8);
    EXPECT_EQ(std::string(sig, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    EXPECT_GT(fs::file_size(png), 1000u);
    EXPECT_NE(p.out.find("| 8 |"), std::string::npos) << p.out;
    EXPECT_NE(p.out.find("llvmpipe"), std::string::npos) << "the device is named\n" << p.out;
}

TEST(Converge, BadArgumentsAreOneLineErrors) {
    const fs::path dir = nbvh::test::temp_dir("converge_bad");
    struct Case {
        std::vector<std::string> extra;
        std::vector<std::string> mention;
    };
    const Case cases[] = {
        {{"--from", "16", "--spp", "8"}, {"--spp", "--from"}},
        {{"--from", "8", "--spp", "64", "--ref-spp", "32"}, {"--ref-spp"}},
        {{"--lod", "5"}, {"--lod"}},
        {{"--from", "0"}, {"--from"}},
        {{"--json", (dir / "same.txt").string(), "--csv", (dir / "same.txt").string()}, {"--json", "--csv"}},
        {{"--json", (dir / "missing" / "c.json").string()}, {"--json"}},
    };
    for (const Case& c : cases) {
        std::vector<std::string> a = {"converge", "default", "--model", tiny_model().string(), "--device", "cpu",
                                      "--width",  "16",      "--height", "16"};
        a.insert(a.end(), c.extra.begin(), c.extra.end());
        const auto r = run_nbvh(a, 120.0);
        EXPECT_EQ(check_clean_error(r, c.mention, false), "") << c.extra.front() << "\n" << r.describe();
    }
    // A missing model file.
    const auto r = run_nbvh({"converge", "default", "--model", (dir / "none.nbvh").string(), "--device", "cpu"}, 60.0);
    EXPECT_EQ(check_clean_error(r, {}, false), "") << r.describe();
}

} // namespace
