// `nbvh render` end to end on lavapipe (label lavapipe): every file in ../shared/scenes/bad/ behaves as
// bad/generated/expected.json and bad/README.md say, at the level of the executable a user runs:
//   error            -> non-zero exit, stderr = "warning: ..." lines then one "nbvh: error: ..." line naming
//                       the problem, no signal, no output image;
//   load_render      -> exit 0, image written, --stats non_finite_pixels == 0;
//   load_skip_bad    -> the same, and a warning;
//   *_or_*           -> either of the above.
// Plus --device gpu without a GPU, and atomic output (a failed render leaves the old image alone).
#include <fstream>
#include <map>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/cli/run_nbvh.h"
#include "tests/support/test_support.h"

namespace {
namespace fs = std::filesystem;
using nbvh::test::check_clean_error;
using nbvh::test::run_nbvh;
using nbvh::test::RunResult;

fs::path bad_dir() { return nbvh::test::scenes_dir() / "bad"; }

std::string read_file(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
}

// What each "error" file's message must mention (the problem, or the file it concerns); the loader's
// unit tests (tests/scene/gltf_bad_inputs_test.cpp) pin the same words.
const std::map<std::string, std::string> ERROR_WORDS = {
    {"generated/bad_magic.glb", "not a GLB"},
    {"generated/broken_json.gltf", "parse error"},
    {"generated/huge_count.gltf", "count 2000000000"},
    {"generated/missing_buffer.gltf", "this_file_does_not_exist.bin"},
    {"generated/scene_index_out_of_range.gltf", "scene 3 does not exist"},
    {"generated/short_buffer.gltf", "short_buffer.bin"},
    {"generated/truncated.glb", "truncated GLB"},
    {"assimp/MissingBin/BoxTextured.gltf", "BoxTextured0.bin"},
    {"assimp/RecursiveNodes/RecursiveNodes.gltf", "cycle"},
    {"assimp/TestNoRootNode/NoScene.gltf", "scene 0 does not exist"},
    {"assimp/wrongTypes/badArray.gltf", "primitives"},
};

// bad/assimp has no machine-readable file: expectations transcribed from bad/README.md.
const std::map<std::string, std::string> ASSIMP_EXPECT = {
    {"BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb", "load_empty_or_error"},
    {"BoxBadNormals-glTF-Binary/BoxBadNormals.glb", "load_render"},
    {"IncorrectVertexArrays/Cube.gltf", "error_or_skip"},
    {"IndexOutOfRange/IndexOutOfRange.gltf", "error_or_skip"},
    {"IndexOutOfRange/AllIndicesOutOfRange.gltf", "load_empty_or_error"},
    {"MissingBin/BoxTextured.gltf", "error"},
    {"RecursiveNodes/RecursiveNodes.gltf", "error"},
    {"TestNoRootNode/NoScene.gltf", "error"},
    {"TestNoRootNode/SceneWithoutNodes.gltf", "load_empty_or_error"},
    {"wrongTypes/badArray.gltf", "error"},
    {"wrongTypes/badNumber.gltf", "error_or_skip"},
};

// Every .gltf/.glb under bad/ (recursively) with its expectation; a file with none fails the test, so a
// new bad file cannot go untested.
std::vector<std::pair<std::string, std::string>> all_cases() {
    std::ifstream in(bad_dir() / "generated" / "expected.json");
    const nlohmann::json expected = nlohmann::json::parse(in);
    std::vector<std::pair<std::string, std::string>> cases;
    for (const auto& e : fs::recursive_directory_iterator(bad_dir())) {
        const std::string ext = e.path().extension().string();
        if (!e.is_regular_file() || (ext != ".gltf" && ext != ".glb")) continue;
        const std::string rel = fs::relative(e.path(), bad_dir()).generic_string();
        std::string expect;
        if (rel.rfind("generated/", 0) == 0 && expected.contains(e.path().filename().string()))
            expect = expected.at(e.path().filename().string()).at("expect");
        else if (rel.rfind("assimp/", 0) == 0 && ASSIMP_EXPECT.count(rel.substr(7)))
            expect = ASSIMP_EXPECT.at(rel.substr(7));
        cases.push_back({rel, expect});
    }
    std::sort(cases.begin(), cases.end());
    return cases;
}

struct Outcome {
    RunResult run;
    bool image = false;          // the output image exists
    int64_t non_finite = -1;     // from --stats (-1: no stats file)
    bool dir_clean = true;       // nothing but the image/stats in the output dir (no temp files left)
    bool depth_times = false;    // --stats has pass_gpu_ms_by_depth for the passes of pass_gpu_ms
    bool provenance = false;     // --stats names the commit, the command line and the settings
};

Outcome render(const fs::path& scene, const fs::path& dir) {
    Outcome o;
    const fs::path out = dir / "out.png", stats = dir / "stats.json";
    o.run = run_nbvh({"render", scene.string(), "--device", "cpu", "--width", "32", "--height", "32", "--spp", "1",
                      "--max-depth", "2", "--out", out.string(), "--stats", stats.string()},
                     60.0);
    o.image = fs::exists(out) && fs::file_size(out) > 0;
    if (fs::exists(stats)) {
        try {
            std::ifstream f(stats);
            const nlohmann::json j = nlohmann::json::parse(f);
            o.non_finite = j.at("non_finite_pixels").get<int64_t>();
            const nlohmann::json &passes = j.at("pass_gpu_ms"), &by_depth = j.at("pass_gpu_ms_by_depth");
            o.depth_times = by_depth.size() == passes.size();
            o.provenance = !j.at("commit").get<std::string>().empty() &&
                           j.at("command_line").get<std::string>().find("--max-depth 2") != std::string::npos &&
                           j.at("settings").at("sort_rays").is_boolean() && j.at("settings").at("seed") == 0;
            for (const auto& [name, ms] : passes.items())
                o.depth_times = o.depth_times && by_depth.contains(name) && by_depth[name].is_array() &&
                                !by_depth[name].empty() && by_depth[name].size() <= 2; // --max-depth 2
        } catch (const std::exception&) {
            o.non_finite = -2;
        }
    }
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path() != out && e.path() != stats) o.dir_clean = false;
    return o;
}

void expect_rendered(const Outcome& o) {
    EXPECT_EQ(o.run.exit_code, 0) << o.run.describe();
    EXPECT_TRUE(o.image) << "no output image";
    EXPECT_EQ(o.non_finite, 0) << "non_finite_pixels in --stats (-1: no stats file)";
    EXPECT_TRUE(o.depth_times) << "pass_gpu_ms_by_depth in --stats";
    EXPECT_TRUE(o.provenance) << "commit, command_line and settings in --stats";
}

// strict: only "warning: " lines may precede the error (files the loader must reject); otherwise the
// loaded scene's informational summary may too (files that load and are refused later, e.g. as empty).
void expect_failed_cleanly(const Outcome& o, const std::string& word, bool strict) {
    const std::string why = check_clean_error(o.run, word.empty() ? std::vector<std::string>{}
                                                                  : std::vector<std::string>{word}, strict);
    EXPECT_EQ(why, "") << o.run.describe();
    EXPECT_FALSE(o.image) << "a failed render must not write the output image";
}

TEST(CliBadScenes, EveryFileBehavesAsExpected) {
    NBVH_REQUIRE_SHARED();
    const auto cases = all_cases();
    ASSERT_GE(cases.size(), 30u) << "bad/ looks incomplete";
    int index = 0;
    for (const auto& [rel, expect] : cases) {
        SCOPED_TRACE(rel + " (expect " + expect + ")");
        ASSERT_FALSE(expect.empty()) << "no expectation for this file: add it to expected.json / ASSIMP_EXPECT";
        const fs::path dir = nbvh::test::temp_dir("cli_bad_" + std::to_string(index++));
        const Outcome o = render(bad_dir() / rel, dir);
        EXPECT_FALSE(o.run.timed_out) << "hang";
        EXPECT_FALSE(o.run.signaled) << o.run.describe();
        EXPECT_TRUE(o.dir_clean) << "stray files left in the output directory";
        const bool warned = o.run.err.find("warning: ") != std::string::npos;
        if (expect == "error") {
            ASSERT_TRUE(ERROR_WORDS.count(rel)) << "no expected wording";
            expect_failed_cleanly(o, ERROR_WORDS.at(rel), true);
        } else if (expect == "load_render") {
            expect_rendered(o);
        } else if (expect == "load_skip_bad") {
            expect_rendered(o);
            EXPECT_TRUE(warned) << "skipping bad parts must warn\n" << o.run.describe();
        } else if (expect == "error_or_skip" || expect == "load_empty_or_error" ||
                   expect == "load_or_clear_error") {
            if (o.run.exit_code == 0) {
                expect_rendered(o);
                if (expect != "load_or_clear_error") {
                    EXPECT_TRUE(warned) << "a repaired/empty input must warn\n" << o.run.describe();
                }
            } else {
                expect_failed_cleanly(o, expect == "load_or_clear_error" ? "out of range" : "", false);
            }
        } else {
            ADD_FAILURE() << "unknown expectation";
        }
    }
}

TEST(CliRenderDevice, GpuWithoutAGpuIsAClearError) {
    const fs::path dir = nbvh::test::temp_dir("cli_gpu");
    const RunResult r = run_nbvh({"render", "default", "--device", "gpu", "--width", "32", "--height", "32",
                                  "--spp", "1", "--out", (dir / "o.png").string()},
                                 60.0);
    if (r.exit_code == 0) GTEST_SKIP() << "this machine has a GPU Vulkan device";
    EXPECT_EQ(check_clean_error(r, {"gpu"}, false), "") << r.describe();
    EXPECT_FALSE(fs::exists(dir / "o.png"));
}

// The user asked for this output path, so an existing image there is replaced by a successful render, but
// a failed render leaves it exactly as it was (writes go to a temporary file renamed into place).
TEST(CliRenderOutput, ExistingImageReplacedOnlyBySuccess) {
    NBVH_REQUIRE_SHARED();
    const fs::path dir = nbvh::test::temp_dir("cli_overwrite");
    const fs::path out = dir / "keep.png";
    {
        std::ofstream f(out, std::ios::binary);
        f << "user's precious image";
    }
    const RunResult bad = run_nbvh({"render", (bad_dir() / "generated" / "bad_magic.glb").string(), "--device", "cpu",
                                    "--width", "32", "--height", "32", "--spp", "1", "--out", out.string()});
    EXPECT_EQ(check_clean_error(bad), "") << bad.describe();
    EXPECT_EQ(read_file(out), "user's precious image");
    for (const char* name : {"keep.png", "keep.exr"}) {
        const RunResult ok = run_nbvh({"render", (bad_dir() / "generated" / "valid_quad.glb").string(), "--device",
                                       "cpu", "--width", "32", "--height", "32", "--spp", "1", "--out",
                                       (dir / name).string()});
        EXPECT_EQ(ok.exit_code, 0) << ok.describe();
    }
    EXPECT_EQ(read_file(out).substr(1, 3), "PNG");
    EXPECT_TRUE(fs::exists(dir / "keep.exr"));
    int files = 0;
    for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file();
    EXPECT_EQ(files, 2) << "temporary files left behind";
}

// --warmup N renders the image N times first, untimed: the written image is the same as without it
// (the renderer restarts its samples each render), and --stats records the setting.
TEST(CliRenderOutput, WarmupRendersTheSameImage) {
    const fs::path dir = nbvh::test::temp_dir("cli_warmup");
    auto render = [&](const char* warmup, const std::string& name) {
        const RunResult r =
            run_nbvh({"render", "default", "--device", "cpu", "--width", "24", "--height", "16", "--spp", "2",
                      "--exposure", "0", "--warmup", warmup, "--out", (dir / (name + ".png")).string(),
                      "--stats", (dir / (name + ".json")).string()});
        EXPECT_EQ(r.exit_code, 0) << r.describe();
    };
    render("0", "cold");
    render("2", "warm");
    EXPECT_EQ(read_file(dir / "cold.png"), read_file(dir / "warm.png"));
    EXPECT_NE(read_file(dir / "warm.json").find("\"warmup\": 2"), std::string::npos);
    const RunResult bad = run_nbvh(
        {"render", "default", "--device", "cpu", "--warmup", "99", "--out", (dir / "x.png").string()});
    EXPECT_EQ(check_clean_error(bad, {"--warmup"}), "") << bad.describe();
}

} // namespace
