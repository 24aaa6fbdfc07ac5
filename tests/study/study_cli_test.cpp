// `nbvh study` end to end on lavapipe (issue 11): a tiny sweep (default scene, 2 node budgets, 2 LoDs,
// 2 cameras, 64x64, CPU-trained tiny models) writes study.csv and study.json with the promised columns,
// finite figures, positive memory and times, the noise floor beside every FLIP, decimated rows at the
// model's bytes; scripts/bench/plot_study.py turns the JSON into valid PNG plots and a table.
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

#include <gtest/gtest.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include "tests/cli/run_nbvh.h"
#include "tests/support/test_support.h"

namespace {
namespace fs = std::filesystem;
using nbvh::test::check_clean_error;
using nbvh::test::run_nbvh;

std::vector<std::string> split(const std::string& line, char sep = ',') {
    std::vector<std::string> out;
    std::stringstream ss(line);
    for (std::string f; std::getline(ss, f, sep);) out.push_back(f);
    if (!line.empty() && line.back() == sep) out.push_back("");
    return out;
}

double num(const std::string& s) { return s.empty() ? NAN : std::stod(s); }

struct Study {
    fs::path dir;
    nbvh::test::RunResult run;
};

bool is_png(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    char sig[8] = {};
    f.read(sig, 8);
    return f.gcount() == 8 && std::string(sig, 8) == std::string("\x89PNG\r\n\x1a\n", 8) &&
           fs::file_size(p) > 1000;
}

nlohmann::json read_json(const fs::path& p) {
    std::ifstream f(p);
    return nlohmann::json::parse(f);
}

// The kept equal-time FLIPs of camera 0 in a --references folder: classical spp -> FLIP.
std::map<int, double> kept_equal_time(const fs::path& refs) {
    std::map<int, double> kept;
    const nlohmann::json j = read_json(refs / "camera_0.json");
    for (const auto& e : j.at("equal_time_flip")) kept[e.at("spp").get<int>()] = e.at("flip").get<double>();
    return kept;
}

// The tiny sweep's command: `nodes` are the node budgets.
std::vector<std::string> tiny_args(const fs::path& out, const std::string& nodes) {
    // Frames timed at another size than the images: their own renderers.
    return {"study",    "default", "--out",      out.string(), "--device",      "cpu", "--backend",
            "cpu",      "--steps", "20",         "--batch",    "256",           "--nodes", nodes,
            "--hash-log2", "12",   "--lods",     "2",          "--threads",     "2",   "--cameras",
            "2",        "--width", "64",         "--height",   "64",            "--spp",   "2",
            "--ref-spp", "8",      "--repeat",   "1",          "--time-width",  "32",  "--time-height",
            "32",       "--save-images"};
}

// The sweep (about a minute on lavapipe).
const Study& tiny_study() {
    static const Study s = [] {
        Study st;
        // One directory per process: ctest runs each TEST of this file as its own process, two of them
        // (this sweep's users) at once under -j2, and temp_dir empties the directory it returns.
        st.dir = nbvh::test::temp_dir("study_tiny_" + std::to_string(::getpid())) / "out";
        setenv("NBVH_VALIDATION", "1", 1); // the child runs with the validation layer; any message fails
        st.run = run_nbvh(tiny_args(st.dir, "31,63"), 500.0);
        unsetenv("NBVH_VALIDATION");
        return st;
    }();
    return s;
}

TEST(Study, TinySweepWritesCsvJsonAndPlots) {
    const Study& s = tiny_study();
    ASSERT_EQ(s.run.exit_code, 0) << s.run.describe();
    EXPECT_EQ(s.run.err.find("vulkan validation"), std::string::npos) << s.run.err;
    EXPECT_NE(s.run.err.find("wrote"), std::string::npos) << s.run.err;
    std::ifstream csv(s.dir / "study.csv");
    ASSERT_TRUE(csv.good());
    std::string header;
    std::getline(csv, header);
    const std::vector<std::string> cols = split(header);
    for (const char* c :
         {"config", "variant", "camera", "nodes", "hash_log2", "lod", "memory_bytes", "frame_ms",
          "classical_frame_ms", "flip", "noise_floor", "within_2x_floor", "converged", "train_seconds",
          "equal_time_spp", "equal_time_flip", "compression", "triangles"})
        EXPECT_NE(std::find(cols.begin(), cols.end(), c), cols.end()) << c << " missing in " << header;
    std::map<std::string, size_t> at;
    for (size_t i = 0; i < cols.size(); ++i) at[cols[i]] = i;
    std::map<std::string, int> per_variant;
    for (std::string line; std::getline(csv, line);) {
        const std::vector<std::string> f = split(line);
        ASSERT_EQ(f.size(), cols.size()) << line;
        const std::string variant = f[at["variant"]];
        if (f[at["camera"]] != "mean") per_variant[variant]++;
        // Every row: positive memory and frame time, a finite FLIP in [0,1] and its noise floor beside it.
        EXPECT_GT(num(f[at["memory_bytes"]]), 0.0) << line;
        EXPECT_GT(num(f[at["frame_ms"]]), 0.0) << line;
        EXPECT_GT(num(f[at["classical_frame_ms"]]), 0.0) << line;
        const double flip = num(f[at["flip"]]), floor = num(f[at["noise_floor"]]);
        EXPECT_TRUE(std::isfinite(flip) && flip >= 0.0 && flip <= 1.0) << line;
        EXPECT_TRUE(std::isfinite(floor) && floor > 0.0 && floor <= 1.0) << line;
        EXPECT_EQ(f[at["within_2x_floor"]] == "1", flip <= 2.0 * floor) << line;
        if (variant == "lod" || variant == "switch" || variant == "cap") {
            EXPECT_GT(num(f[at["nodes"]]), 0.0) << line;
            EXPECT_GT(num(f[at["train_seconds"]]), 0.0) << line;
            EXPECT_GT(num(f[at["compression"]]), 1.0) << line; // 384k triangles vs a 2^12 grid
            const double capped = num(f[at["leaf_cap_fraction"]]); // rays truncated by the leaf budget
            EXPECT_TRUE(std::isfinite(capped) && capped >= 0.0 && capped <= 1.0) << line;
            if ((variant == "lod" && f[at["lod"]] == "0") || variant == "switch") {
                EXPECT_GE(num(f[at["equal_time_spp"]]), 1.0) << line;
                EXPECT_TRUE(std::isfinite(num(f[at["equal_time_flip"]]))) << line;
            }
        }
        if (variant == "decimated") {
            EXPECT_GT(num(f[at["triangles"]]), 0.0) << line;
        }
    }
    // 2 configs x 2 cameras: 2 LoDs + LoD switch each, a decimated row each, the raised leaf budget for the
    // middle configuration; 2 classical.
    EXPECT_EQ(per_variant["lod"], 8);
    EXPECT_EQ(per_variant["switch"], 4);
    EXPECT_EQ(per_variant["cap"], 2);
    EXPECT_EQ(per_variant["decimated"], 4);
    EXPECT_EQ(per_variant["classical"], 2);

    std::ifstream jf(s.dir / "study.json");
    const nlohmann::json j = nlohmann::json::parse(jf);
    for (const char* k : {"device", "driver", "commit", "command_line", "started_utc"})
        EXPECT_FALSE(j[k].get<std::string>().empty()) << k;
    EXPECT_TRUE(j["complete"].get<bool>());
    EXPECT_TRUE(j["vulkan_validation"].get<bool>());
    EXPECT_EQ(j["settings"]["time_width"].get<int>(), 32);
    // The image renderers (2 cameras' classical ones, the hybrid, the decimated scene's) split half of the
    // device's memory: an eighth each.
    EXPECT_FLOAT_EQ(j["settings"]["image_wave_memory_share"].get<float>(), 0.125f);
    EXPECT_NE(j["command_line"].get<std::string>().find("study default"), std::string::npos);
    ASSERT_EQ(j["cameras"].size(), 2u);
    for (const auto& c : j["cameras"]) EXPECT_GT(c["noise_floor"].get<double>(), 0.0);
    ASSERT_EQ(j["configs"].size(), 2u);
    for (const auto& c : j["configs"]) {
        EXPECT_GT(c["neural_bytes"]["total"].get<uint64_t>(), c["neural_bytes"]["grid"].get<uint64_t>());
        EXPECT_EQ(c["lod_node_counts"].size(), 2u);
        ASSERT_TRUE(c.contains("decimation_seconds")) << c.dump(); // the worker thread's meshoptimizer + BVHs
        EXPECT_GT(c["decimation_seconds"].get<double>(), 0.0);
    }
    // Decimated rows: the meshes at the bytes of the LoD-0 model, within 5 %.
    std::map<int, uint64_t> lod0_bytes;
    for (const auto& r : j["rows"])
        if (r["variant"] == "lod" && r["lod"] == 0) lod0_bytes[r["config"].get<int>()] = r["memory_bytes"];
    for (const auto& r : j["rows"])
        if (r["variant"] == "decimated") {
            const double target = double(lod0_bytes.at(r["config"].get<int>()));
            EXPECT_NEAR(r["memory_bytes"].get<double>() / target, 1.0, 0.05) << r.dump();
        }
    for (const char* img : {"reference_cam0.png", "hybrid_cam0.png", "decimated_cam0.png"})
        EXPECT_TRUE(fs::exists(s.dir / img)) << img;

    // The plots and the table of scripts/bench/plot_study.py.
    const fs::path python = "/usr/bin/python3"; // Debian's, with python3-matplotlib (scripts/setup.sh)
    const auto probe = nbvh::test::run_command(python, {"-c", "import matplotlib"}, 60.0);
    if (probe.exit_code != 0)
        GTEST_SKIP()
            << "python3-matplotlib is not installed (scripts/setup.sh installs it): plots not checked";
    const fs::path out = nbvh::test::temp_dir("study_plots");
    const auto r =
        nbvh::test::run_command(python,
                                {(nbvh::test::source_dir() / "scripts/bench/plot_study.py").string(),
                                 (s.dir / "study.json").string(), out.string()},
                                120.0);
    ASSERT_EQ(r.exit_code, 0) << r.describe();
    for (const char* png : {"error_vs_time.png", "error_vs_memory.png", "training_vs_error.png"})
        EXPECT_TRUE(is_png(out / png)) << png;
    std::ifstream t(out / "table.md");
    std::stringstream text;
    text << t.rdbuf();
    EXPECT_NE(text.str().find("noise floor"), std::string::npos);
    EXPECT_NE(text.str().find("that meet the issue's rule"), std::string::npos) << "per-camera rule count";
    EXPECT_NE(text.str().find("llvmpipe"), std::string::npos) << "the device is named";
    EXPECT_NE(text.str().find("FLIP, same seed"), std::string::npos) << "the shared-seed column";
}

// A time budget stops before a configuration that would end past it; what ran is written, marked incomplete.
TEST(Study, BudgetStopsBetweenConfigurations) {
    const fs::path dir = nbvh::test::temp_dir("study_budget") / "out";
    const auto r = run_nbvh({"study",
                             "default",
                             "--out",
                             dir.string(),
                             "--device",
                             "cpu",
                             "--backend",
                             "cpu",
                             "--steps",
                             "5",
                             "--batch",
                             "128",
                             "--nodes",
                             "15,31",
                             "--hash-log2",
                             "10",
                             "--lods",
                             "1",
                             "--threads",
                             "2",
                             "--cameras",
                             "1",
                             "--width",
                             "16",
                             "--height",
                             "16",
                             "--spp",
                             "1",
                             "--ref-spp",
                             "2",
                             "--repeat",
                             "1",
                             "--no-decimation",
                             "--no-equal-time",
                             "--budget-minutes",
                             "0.0001"},
                            300.0);
    ASSERT_EQ(r.exit_code, 0) << r.describe();
    const nlohmann::json j = read_json(dir / "study.json");
    EXPECT_FALSE(j["complete"].get<bool>());
    EXPECT_EQ(j["configs_done"].get<int>(), 1);
    EXPECT_EQ(j["configs_planned"].get<int>(), 2);
    EXPECT_NE(j["stop_reason"].get<std::string>().find("budget"), std::string::npos);
    EXPECT_EQ(j["configs"].size(), 1u);
}

// The sweep keeps its hybrid renderers and swaps each configuration's model in (apply()): the second
// configuration's rows are those of a study that trains only it, with fresh renderers (CPU training is
// bit-reproducible; same seed). Frame times aside, every figure of those rows is equal.
TEST(Study, ASweepsLaterConfigurationRendersAsAFreshStudy) {
    const Study& s = tiny_study();
    ASSERT_EQ(s.run.exit_code, 0) << s.run.describe();
    const fs::path alone = nbvh::test::temp_dir("study_alone") / "out";
    const auto r = run_nbvh(tiny_args(alone, "63"), 500.0);
    ASSERT_EQ(r.exit_code, 0) << r.describe();
    auto rows_of = [](const fs::path& dir, int config) {
        const nlohmann::json j = read_json(dir / "study.json");
        std::vector<nlohmann::json> out;
        for (const auto& row : j["rows"])
            if (row["config"].get<int>() == config && row["variant"] != "classical") out.push_back(row);
        return out;
    };
    const std::vector<nlohmann::json> swept = rows_of(s.dir, 1), fresh = rows_of(alone, 0);
    ASSERT_EQ(swept.size(), fresh.size());
    ASSERT_FALSE(swept.empty());
    for (size_t i = 0; i < swept.size(); ++i) {
        for (const char* k : {"variant", "camera", "lod", "nodes", "memory_bytes", "flip", "flip_same_seed",
                              "queries_per_ray", "triangles"})
            EXPECT_EQ(swept[i].value(k, nlohmann::json()), fresh[i].value(k, nlohmann::json()))
                << k << "\n" << swept[i].dump() << "\n" << fresh[i].dump();
    }
    // Control: the first configuration (another model) renders other images.
    const std::vector<nlohmann::json> first = rows_of(s.dir, 0);
    ASSERT_FALSE(first.empty());
    EXPECT_NE(first[0]["flip_same_seed"], swept[0]["flip_same_seed"]);
}

// scripts/bench/study_multi.sh: parts of the sweep run in parallel (here two lavapipe processes standing in
// for two GPUs) and merge_study.py joins them: every configuration once, the reference rows once.
TEST(Study, PartsRunInParallelAndMergeIntoOneStudy) {
    const fs::path dir = nbvh::test::temp_dir("study_multi_" + std::to_string(::getpid())) / "out";
    const auto r =
        nbvh::test::run_command("/usr/bin/env",
                                {"GPUS=2",
                                 "PART_DEVICE=cpu",
                                 "BACKEND=cpu",
                                 "NBVH=" + nbvh::test::nbvh_exe().string(),
                                 "PARTS=31:12 63:12",
                                 "CAP_AT=63:12",
                                 "WIDTH=32",
                                 "HEIGHT=32",
                                 "SPP=2",
                                 "REF_SPP=8",
                                 "TIME_WIDTH=32",
                                 "TIME_HEIGHT=32",
                                 "LODS=1",
                                 "CAMERAS=2",
                                 "bash",
                                 (nbvh::test::source_dir() / "scripts/bench/study_multi.sh").string(),
                                 "default",
                                 dir.string(),
                                 "--steps",
                                 "20",
                                 "--batch",
                                 "256",
                                 "--threads",
                                 "1"},
                                300.0);
    ASSERT_EQ(r.exit_code, 0) << r.describe();
    std::ifstream f(dir / "study.json");
    ASSERT_TRUE(f.good()) << r.describe();
    const nlohmann::json j = nlohmann::json::parse(f);
    EXPECT_TRUE(j.at("complete").get<bool>());
    ASSERT_EQ(j.at("configs").size(), 2u);
    EXPECT_EQ(j.at("configs")[0].at("nodes_target").get<int>(), 31);
    EXPECT_EQ(j.at("configs")[1].at("nodes_target").get<int>(), 63);
    EXPECT_EQ(j.at("parts").size(), 2u);
    int classical = 0, lod = 0, cap = 0;
    for (const auto& row : j.at("rows")) {
        if (row.at("variant") == "classical") ++classical;
        if (row.at("variant") == "lod") ++lod;
        if (row.at("variant") == "cap") ++cap;
    }
    EXPECT_EQ(classical, 2) << "one reference row per camera, not one per part";
    EXPECT_EQ(lod, 4) << "2 configurations x 2 cameras";
    EXPECT_EQ(cap, 2) << "the raised-leaf-budget rows once: the part whose middle configuration is CAP_AT";
    EXPECT_EQ(j.at("settings").at("cap_study").get<int>(), 64);
    EXPECT_TRUE(fs::exists(dir / "part_0" / "study.json") && fs::exists(dir / "part_1" / "study.json"));
    // The cameras' classical side was rendered once, a camera per GPU, and every part took it from there.
    for (const char* c : {"camera_0.json", "camera_1.json", "camera_0_reference.png", "camera_1_floor.png"})
        EXPECT_TRUE(fs::exists(dir / "references" / c)) << c;
    for (const char* part : {"part_0", "part_1"}) {
        const nlohmann::json pj = read_json(dir / part / "study.json");
        for (const auto& cam : pj.at("cameras")) EXPECT_TRUE(cam.at("from_references").get<bool>()) << part;
    }
}

// --references: a second study of the same setup takes each camera's classical side from the folder and
// gives the same figures to the last bit; a folder made by another setup, or damaged, is a one-line error.
TEST(Study, ReferencesAreReusedAndGuarded) {
    const fs::path dir = nbvh::test::temp_dir("study_refs_" + std::to_string(::getpid()));
    const std::vector<std::string> a = {
        "study",        "default", "--device",      "cpu", "--backend",    "cpu",
        "--steps",      "10",      "--batch",       "128", "--nodes",      "15",
        "--hash-log2",  "10",      "--lods",        "1",   "--threads",    "2",
        "--cameras",    "1",       "--width",       "32",  "--height",     "32",
        "--spp",        "2",       "--ref-spp",     "8",   "--repeat",     "1",
        "--time-width", "16",      "--time-height", "16",  "--references", (dir / "refs").string()};
    auto with = [&](std::vector<std::string> extra) {
        std::vector<std::string> v = a;
        v.insert(v.end(), extra.begin(), extra.end());
        return v;
    };
    // The first run keeps the equal-time FLIPs of every eighth up to 16x the compared spp (lavapipe's
    // hybrid frames take 2-5x the classical one), so both runs' equal-time rows fall among them.
    const auto first = run_nbvh(with({"--out", (dir / "a").string(), "--equal-time-upto", "16"}), 300.0);
    ASSERT_EQ(first.exit_code, 0) << first.describe();
    const std::map<int, double> kept = kept_equal_time(dir / "refs");
    for (int spp = 2; spp <= 32; ++spp)
        EXPECT_EQ(kept.count(spp), 1u) << spp; // the compared 2 spp, then eighths
    const auto second = run_nbvh(with({"--out", (dir / "b").string()}), 300.0);
    ASSERT_EQ(second.exit_code, 0) << second.describe();
    EXPECT_NE(second.err.find("classical side from --references"), std::string::npos) << second.describe();
    const nlohmann::json ra = read_json(dir / "a" / "study.json").at("rows");
    const nlohmann::json rb = read_json(dir / "b" / "study.json").at("rows");
    ASSERT_EQ(ra.size(), rb.size());
    int equal_time_rows = 0;
    for (size_t i = 0; i < ra.size(); ++i) {
        for (const char* k : {"variant", "flip", "noise_floor", "classical_frame_ms"})
            EXPECT_EQ(ra[i].at(k), rb[i].at(k)) << k << " of row " << i;
        // Equal time follows the hybrid's frame time, measured anew in each run: each run's equal-time
        // FLIP is the one the first run kept for that spp.
        for (const nlohmann::json* row : {&ra[i], &rb[i]}) {
            if (row->at("variant") != "lod") continue;
            const int spp = row->at("equal_time_spp").get<int>();
            ASSERT_EQ(kept.count(spp), 1u) << "equal-time spp " << spp << " beyond the kept ones";
            EXPECT_EQ(row->at("equal_time_flip").get<double>(), kept.at(spp)) << "row " << i;
            ++equal_time_rows;
        }
    }
    EXPECT_EQ(equal_time_rows, 2) << "LoD 0 of each run";

    const auto other = run_nbvh(with({"--out", (dir / "c").string(), "--max-depth", "4"}), 300.0);
    EXPECT_EQ(check_clean_error(other, {"--references", "max_depth"}), "") << other.describe();
    std::ofstream(dir / "refs" / "camera_0.json") << "{ not json";
    const auto damaged = run_nbvh(with({"--out", (dir / "d").string()}), 300.0);
    EXPECT_EQ(check_clean_error(damaged, {"camera_0.json"}), "") << damaged.describe();
    const auto only = run_nbvh(with({"--out", (dir / "e").string(), "--reference-cameras", "0"}), 60.0);
    EXPECT_EQ(check_clean_error(only, {"--reference-cameras", "--references-only"}), "") << only.describe();
}

TEST(Study, BadOptionsFailBeforeAnyWork) {
    const fs::path dir = nbvh::test::temp_dir("study_bad");
    auto r = run_nbvh({"study", "default", "--out", (dir / "o").string(), "--device", "cpu", "--spp", "64",
                       "--ref-spp", "16"});
    EXPECT_EQ(check_clean_error(r, {"--ref-spp"}), "") << r.describe();
    r = run_nbvh({"study", "default", "--out", (dir / "no" / "such" / "o").string(), "--device", "cpu"});
    EXPECT_EQ(check_clean_error(r, {"--out"}), "") << r.describe();
    r = run_nbvh({"study", "default", "--out", (dir / "o").string(), "--hash-log2", "2"});
    EXPECT_EQ(check_clean_error(r, {"--hash-log2"}), "") << r.describe();
    r = run_nbvh({"study", "default", "--out", (dir / "o").string(), "--device", "gpu:x"});
    EXPECT_EQ(check_clean_error(r, {"--device", "gpu:x"}), "") << r.describe();
    // gpu:N beyond the machine's GPUs (on CI: any N, lavapipe is no GPU) fails before the first training.
    r = run_nbvh(
        {"study", "default", "--out", (dir / "o").string(), "--device", "gpu:63", "--backend", "cpu"});
    EXPECT_EQ(check_clean_error(r, {"--device gpu:63"}), "") << r.describe();
    EXPECT_FALSE(fs::exists(dir / "o" / "study.json"));
}

} // namespace
