// Scripted viewer sessions end to end (issue 13's acceptance): `nbvh view --script` under Xvfb on
// lavapipe with the validation layer on, checked through its screenshots and `report` JSON files.
// A slider change is an upload (the renderer-build counter does not move) and changes the image; the
// split view shows the hybrid film left of the line and the classical one right of it; the FLIP view is
// bright where the tiny model is poor; dropped bad files leave the viewer running with the CLI's error
// line in the panel; live CPU training lowers the loss and changes the image.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "engine/core/image.h"
#include "tests/cli/run_nbvh.h"
#include "tests/support/test_support.h"

namespace nbvh {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::run_command;
using test::run_nbvh;
using test::RunResult;

fs::path find_xvfb_run() {
    for (const char* dir : {"/usr/bin", "/usr/local/bin", "/bin"})
        if (fs::exists(fs::path(dir) / "xvfb-run")) return fs::path(dir) / "xvfb-run";
    return {};
}

#define REQUIRE_XVFB()                                                                            \
    do {                                                                                          \
        if (find_xvfb_run().empty()) GTEST_SKIP() << "xvfb-run not installed (Debian: xvfb)";     \
    } while (0)

const fs::path& tiny_model() { return nbvh::test::tiny_default_model("viewer_script_model"); }

// Another model of the same scene and assets (more steps: other weights and cut), for model swaps.
const fs::path& tiny_model_b() {
    static const fs::path model = [] {
        const fs::path m = tiny_model().parent_path() / "tiny_b.nbvh";
        const RunResult r =
            run_nbvh({"train", "default", "--backend", "cpu", "--steps", "40", "--batch", "256", "--nodes", "127",
                      "--hash-log2", "12", "--lods", "2", "--threads", "2", "--seed", "7", "--out", m.string()},
                     120.0);
        EXPECT_EQ(r.exit_code, 0) << r.describe();
        return m;
    }();
    return model;
}

// Writes `script` into `dir` and runs `nbvh view default --script` at 160x90 on lavapipe.
RunResult run_view(const fs::path& dir, const std::string& script, std::vector<std::string> extra = {},
                   double timeout_s = 300.0, bool ui = false) {
    const fs::path file = dir / "session.txt";
    std::ofstream(file) << script;
    std::vector<std::string> args = {"-a", "env", "NBVH_VALIDATION=1", test::nbvh_exe().string(), "view", "default",
                                     "--device", "cpu", "--script", file.string()};
    for (const char* a : {"--width", ui ? "480" : "160", "--height", ui ? "270" : "90"}) args.push_back(a);
    if (!ui) args.push_back("--hide-ui");
    args.insert(args.end(), extra.begin(), extra.end());
    return run_command(find_xvfb_run(), args, timeout_s, dir);
}

void expect_clean(const RunResult& r) {
    ASSERT_EQ(r.exit_code, 0) << r.describe();
    EXPECT_NE(r.err.find("view: Vulkan validation on"), std::string::npos) << r.describe();
    EXPECT_EQ(r.err.find("vulkan validation:"), std::string::npos) << r.describe();
}

json read_json(const fs::path& p) {
    std::ifstream f(p);
    EXPECT_TRUE(f.good()) << p;
    return json::parse(f, nullptr, false);
}

// Mean absolute difference per channel over columns [x0, x1) (display values, linear after decode).
double mean_diff(const Image& a, const Image& b, int x0, int x1) {
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    double sum = 0.0;
    size_t n = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = x0; x < x1; ++x)
            for (int c = 0; c < 3; ++c, ++n)
                sum += std::fabs(a.data[(size_t(y) * a.width + x) * a.channels + c] -
                                 b.data[(size_t(y) * b.width + x) * b.channels + c]);
    return n ? sum / double(n) : 0.0;
}

TEST(ViewerSession, SliderChangesAreUploadsAndChangeTheImage) {
    REQUIRE_XVFB();
    const fs::path dir = test::temp_dir("viewer_session_sliders");
    const RunResult r = run_view(dir, "set max_spp 2\n"
                                      "frames 3\nscreenshot lod0.png\nreport r0.json\n"
                                      "set lod 1\nframes 3\nscreenshot lod1.png\n"
                                      "set neural off\nframes 3\nscreenshot classical.png\n"
                                      "set neural on\nset secondary_lod 1\nset max_depth 4\nframes 2\n"
                                      "orbit 40 0\nframes 2\nreport r1.json\n"
                                      // Control: material overrides baked into a classical film need a build.
                                      "set override_material on\nset neural off\nframes 1\nreport r2.json\n",
                                 {"--model", tiny_model().string()});
    expect_clean(r);
    const json r0 = read_json(dir / "r0.json"), r1 = read_json(dir / "r1.json");
    EXPECT_EQ(r0["renderer_builds"], 1);
    EXPECT_EQ(r0["live_updates"], 0);
    // Four setting changes in three frames (the last two applied together), a camera move: no rebuild.
    EXPECT_EQ(r1["renderer_builds"], 1) << r1.dump(2);
    EXPECT_EQ(r1["live_updates"], 3) << r1.dump(2);
    EXPECT_EQ(r1["lod"], 1);
    EXPECT_EQ(r1["max_depth"], 4);
    EXPECT_EQ(r1["samples"], 2); // restarted by each change, stopped at max spp
    EXPECT_EQ(read_json(dir / "r2.json")["renderer_builds"], 2); // the counter counts
    const Image lod0 = load_image((dir / "lod0.png").string()), lod1 = load_image((dir / "lod1.png").string());
    const Image classical = load_image((dir / "classical.png").string());
    EXPECT_GT(mean_diff(lod0, lod1, 0, 160), 1e-4);     // the LoD slider changed the image
    EXPECT_GT(mean_diff(lod0, classical, 0, 160), 5e-3); // neural off shows the true scene
}

// A model of the same assets, dropped on the window, replaces the model as an upload: no renderer is
// built, the image changes, the node counts follow the new model, and the split view's classical
// reference keeps its film. The leaf budget is an upload too, and the stats count the rays it truncates.
TEST(ViewerSession, ModelSwapIsAnUploadAndLeafCapHitsAreCounted) {
    REQUIRE_XVFB();
    const fs::path dir = test::temp_dir("viewer_session_swap");
    const RunResult r = run_view(dir, "set max_spp 2\n"
                                      "frames 3\nscreenshot a.png\nreport r0.json\n"
                                      "drop " + tiny_model_b().string() + "\nframes 3\nscreenshot b.png\nreport r1.json\n"
                                      "set view split\nframes 3\nreport r2.json\n"
                                      "drop " + tiny_model().string() + "\nframes 1\nreport r3.json\n"
                                      "set view image\nset max_leaves 1\nframes 1\nreport r4.json\n"
                                      "set max_leaves 256\nframes 1\nreport r5.json\n",
                                 {"--model", tiny_model().string()});
    expect_clean(r);
    const json r0 = read_json(dir / "r0.json"), r1 = read_json(dir / "r1.json"), r2 = read_json(dir / "r2.json");
    const json r3 = read_json(dir / "r3.json"), r4 = read_json(dir / "r4.json"), r5 = read_json(dir / "r5.json");
    EXPECT_EQ(r1["status"], "opened " + tiny_model_b().string());
    EXPECT_EQ(r1["renderer_builds"], 1) << r1.dump(2);
    EXPECT_EQ(r1["model_swaps"], 1);
    EXPECT_NE(r1["lod_node_counts"], r0["lod_node_counts"]); // the new model's cut
    EXPECT_EQ(r1["samples"], 2);
    EXPECT_GT(mean_diff(load_image((dir / "a.png").string()), load_image((dir / "b.png").string()), 0, 160), 1e-3);
    // Swapping back while the split view runs: the classical reference is neither rebuilt nor restarted.
    EXPECT_EQ(r2["reference_samples"], 2);
    EXPECT_EQ(r3["model_swaps"], 2);
    EXPECT_EQ(r3["renderer_builds"], 1);
    EXPECT_EQ(r3["reference_builds"], 1);
    EXPECT_EQ(r3["reference_samples"], 2) << "the reference film restarted on a model swap";
    // Leaf budget 1: rays that need a second leaf are truncated and counted; 256: none is.
    EXPECT_EQ(r4["max_leaves"], 1);
    EXPECT_GT(r4["main"]["neural"]["leaf_cap_rays"].get<uint64_t>(), 0u) << r4["main"].dump(2);
    EXPECT_EQ(r5["main"]["neural"]["leaf_cap_rays"], 0);
    EXPECT_EQ(r5["renderer_builds"], 1);
}

TEST(ViewerSession, SplitViewShowsBothHalves) {
    REQUIRE_XVFB();
    const fs::path dir = test::temp_dir("viewer_session_split");
    // Both films stop at 2 spp with the same seed: the split view's halves are those films exactly
    // (a renderer switched by apply() renders as a fresh one, engine test).
    const RunResult r = run_view(dir, "set max_spp 2\n"
                                      "frames 3\nscreenshot hybrid.png\n"
                                      "set neural off\nframes 3\nscreenshot classical.png\n"
                                      "set neural on\nset view split\nset split 0.5\nframes 3\nscreenshot split.png\n"
                                      "set split 0.25\nframes 1\nscreenshot split25.png\nreport r.json\n",
                                 {"--model", tiny_model().string()});
    expect_clean(r);
    const Image hybrid = load_image((dir / "hybrid.png").string());
    const Image classical = load_image((dir / "classical.png").string());
    const Image split = load_image((dir / "split.png").string()), split25 = load_image((dir / "split25.png").string());
    // The knot spans the middle: the two films differ on both sides of the line (else the test is blind).
    ASSERT_GT(mean_diff(hybrid, classical, 0, 80), 1e-3);
    ASSERT_GT(mean_diff(hybrid, classical, 80, 160), 1e-3);
    EXPECT_EQ(mean_diff(split, hybrid, 0, 80), 0.0);
    EXPECT_EQ(mean_diff(split, classical, 80, 160), 0.0);
    EXPECT_EQ(mean_diff(split25, hybrid, 0, 40), 0.0); // the line moved without restarting either film
    EXPECT_EQ(mean_diff(split25, classical, 40, 160), 0.0);
    const json j = read_json(dir / "r.json");
    EXPECT_EQ(j["view"], "split");
    EXPECT_EQ(j["reference_builds"], 1);
    EXPECT_EQ(j["renderer_builds"], 1);
    EXPECT_EQ(j["reference_samples"], 2);
}

TEST(ViewerSession, FlipViewIsBrightWhereTheModelIsPoor) {
    REQUIRE_XVFB();
    const fs::path dir = test::temp_dir("viewer_session_flip");
    const RunResult r = run_view(dir, "set max_spp 4\n"
                                      "frames 5\nscreenshot hybrid.png\n"
                                      "set neural off\nframes 5\nscreenshot classical.png\nset neural on\n"
                                      "set view flip\nframes 5\ncompare\nframes 1\nscreenshot flip.png\nreport r.json\n"
                                      "set view difference\ncompare\nframes 1\nscreenshot difference.png\n",
                                 {"--model", tiny_model().string()});
    expect_clean(r);
    const json j = read_json(dir / "r.json");
    ASSERT_TRUE(j.contains("flip")) << j.dump(2);
    EXPECT_GT(j["flip"]["mean"].get<double>(), 0.05) << "a 63-node, 20-step model is far from the truth";
    EXPECT_EQ(j["flip"]["samples"], 4);
    EXPECT_EQ(j["flip"]["reference_samples"], 4);
    const Image hybrid = load_image((dir / "hybrid.png").string());
    const Image classical = load_image((dir / "classical.png").string());
    const Image flip = load_image((dir / "flip.png").string()), diff = load_image((dir / "difference.png").string());
    // Where hybrid and classical differ strongly (the knot), the heat map is brighter than elsewhere.
    double hot = 0.0, cold = 0.0, dhot = 0.0, dcold = 0.0;
    size_t nh = 0, nc = 0;
    for (size_t i = 0; i < flip.pixel_count(); ++i) {
        double d = 0.0, heat = 0.0, dd = 0.0;
        for (int c = 0; c < 3; ++c) {
            d += std::fabs(hybrid.data[i * 4 + c] - classical.data[i * 4 + c]);
            heat += flip.data[i * 4 + c];
            dd += diff.data[i * 4 + c];
        }
        if (d > 0.3) hot += heat, dhot += dd, ++nh;
        else if (d == 0.0) cold += heat, dcold += dd, ++nc;
    }
    ASSERT_GT(nh, 50u);
    ASSERT_GT(nc, 50u);
    EXPECT_GT(hot / double(nh), 4.0 * cold / double(nc)) << hot / double(nh) << " vs " << cold / double(nc);
    EXPECT_GT(dhot / double(nh), 0.1);
    EXPECT_EQ(dcold, 0.0); // identical pixels are black in the difference view
}

TEST(ViewerSession, DroppedFilesOpenOrShowTheCliError) {
    REQUIRE_XVFB();
    const fs::path dir = test::temp_dir("viewer_session_drop");
    std::ofstream(dir / "garbage.nbvh") << "this is not a model";
    std::ofstream(dir / "broken.gltf") << "{ \"asset\": ";
    std::ofstream(dir / "notes.txt") << "hello";
    // The CLI's line for the same bad scene.
    const RunResult cli = run_nbvh({"render", (dir / "broken.gltf").string(), "--device", "cpu"}, 60.0);
    ASSERT_NE(cli.exit_code, 0);
    const std::vector<std::string> lines = test::split_lines(cli.err);
    ASSERT_FALSE(lines.empty());
    const std::string cli_line = lines.back();
    ASSERT_EQ(cli_line.rfind("nbvh: error: ", 0), 0u) << cli.describe();

    const RunResult r = run_view(dir, "frames 1\n"
                                      "drop " + (dir / "broken.gltf").string() + "\nframes 1\nreport r1.json\n"
                                      "drop " + (dir / "garbage.nbvh").string() + "\nframes 1\nreport r2.json\n"
                                      "drop " + (dir / "notes.txt").string() + "\nframes 1\nreport r3.json\n"
                                      "drop " + tiny_model().string() + "\nframes 2\nreport r4.json\n"
                                      "set view split\nframes 2\nscreenshot alive.png\nreport r5.json\n");
    expect_clean(r);
    const json r1 = read_json(dir / "r1.json"), r2 = read_json(dir / "r2.json"), r3 = read_json(dir / "r3.json");
    const json r4 = read_json(dir / "r4.json"), r5 = read_json(dir / "r5.json");
    EXPECT_EQ(r1["status"], "error: " + cli_line.substr(13)) << "the CLI's line";
    EXPECT_EQ(r1["scene"], "default");
    EXPECT_NE(r2["status"].get<std::string>().find("garbage.nbvh"), std::string::npos) << r2["status"];
    EXPECT_EQ(r2["status"].get<std::string>().rfind("error: ", 0), 0u);
    EXPECT_EQ(r3["status"], "error: cannot open '" + (dir / "notes.txt").string() +
                                "': expected a .gltf, .glb or .nbvh file");
    EXPECT_EQ(r3["has_model"], false);
    // A good model dropped on the scene it was trained for: the view becomes hybrid.
    EXPECT_EQ(r4["has_model"], true) << r4["status"];
    EXPECT_EQ(r4["status"], "opened " + tiny_model().string());
    EXPECT_NE(r4["main"].value("neural", json()).value("path", ""), "");
    EXPECT_EQ(r5["view"], "split");
    EXPECT_TRUE(fs::exists(dir / "alive.png"));
    // A valid scene the model does not answer: opened without the model.
    if (const auto shared = test::shared_dir()) {
        const fs::path quad = test::scenes_dir() / "bad" / "generated" / "valid_quad.glb";
        const RunResult q = run_view(dir, "drop " + tiny_model().string() + "\nframes 1\n"
                                          "drop " + quad.string() + "\nframes 2\nreport q.json\n");
        expect_clean(q);
        const json qj = read_json(dir / "q.json");
        EXPECT_EQ(qj["scene"], quad.string());
        EXPECT_EQ(qj["has_model"], false);
        EXPECT_NE(qj["status"].get<std::string>().find("without the model"), std::string::npos) << qj["status"];
    }
}

TEST(ViewerSession, LiveCpuTrainingLowersTheLossAndChangesTheImage) {
    REQUIRE_XVFB();
    const fs::path dir = test::temp_dir("viewer_session_train");
    const RunResult r = run_view(dir, "set max_spp 2\nframes 3\nscreenshot before.png\nreport r0.json\n"
                                      "set train_backend cpu\nset train_steps 60\nset train_nodes 63\n"
                                      "set train_batch 512\nset train_hash_log2 12\nset train_threads 1\n"
                                      "set train_snapshot 20\ntrain start\ntrain wait 400\n"
                                      "frames 3\nscreenshot after.png\nreport r1.json\ntrain save live.nbvh\n"
                                      "set view loss\nframes 2\nscreenshot loss.png\nreport r2.json\n",
                                 {}, 600.0);
    expect_clean(r);
    const json r0 = read_json(dir / "r0.json"), t = read_json(dir / "r1.json");
    EXPECT_EQ(r0["has_model"], false); // the knot starts classical: the default scene flags it neural
    EXPECT_EQ(t["training"]["state"], "done") << t.dump(2);
    EXPECT_EQ(t["training"]["step"], 60);
    EXPECT_EQ(t["training"]["snapshots"], 3); // after steps 20, 40 and the final model
    EXPECT_GT(t["training"]["nodes"].get<int>(), 1);
    const std::vector<double> loss = t["training"]["loss_history"].get<std::vector<double>>();
    ASSERT_EQ(loss.size(), 60u);
    double first = 0.0, last = 0.0;
    for (size_t i = 0; i < 10; ++i) first += loss[i], last += loss[loss.size() - 1 - i];
    EXPECT_LT(last, 0.9 * first) << "mean loss of the first 10 steps " << first / 10 << ", last 10 " << last / 10;
    EXPECT_EQ(t["has_model"], true);
    // The first snapshot binds the scene to a model (a build); the next ones are uploads (one or two: the
    // final model may replace the step-40 snapshot before a frame takes it).
    EXPECT_EQ(t["renderer_builds"], 2) << t.dump(2);
    EXPECT_GE(t["model_swaps"].get<int>(), 1) << t.dump(2);
    const Image before = load_image((dir / "before.png").string()), after = load_image((dir / "after.png").string());
    EXPECT_GT(mean_diff(before, after, 0, 160), 1e-3);
    // The loss view of the trained model: the knot's leaves in several colours (their losses differ).
    const json l = read_json(dir / "r2.json");
    EXPECT_EQ(l["view"], "loss");
    EXPECT_EQ(l["loss_view"]["available"], true);
    EXPECT_GE(l["loss_view"]["leaves"].get<int>(), 4) << l.dump(2);
    EXPECT_LT(l["loss_view"]["lo"].get<double>(), 0.8 * l["loss_view"]["hi"].get<double>()) << l.dump(2);
    EXPECT_EQ(l["renderer_builds"], 2); // no reference renderer, no rebuild
    const Image loss_png = load_image((dir / "loss.png").string());
    std::set<uint32_t> colours;
    size_t coloured = 0;
    for (size_t i = 0; i < loss_png.pixel_count(); ++i) {
        const float* p = loss_png.data.data() + i * loss_png.channels;
        if (std::fabs(p[0] - p[1]) + std::fabs(p[1] - p[2]) < 0.05f) continue; // grey: triangles, misses
        ++coloured;
        colours.insert(uint32_t(p[0] * 15.0f + 0.5f) | uint32_t(p[1] * 15.0f + 0.5f) << 4 |
                       uint32_t(p[2] * 15.0f + 0.5f) << 8);
    }
    EXPECT_GT(coloured, 100u);
    EXPECT_GE(colours.size(), 6u) << "the loss view is (nearly) uniform";
    ASSERT_TRUE(fs::exists(dir / "live.nbvh"));
    const RunResult info = run_nbvh({"info", (dir / "live.nbvh").string()}, 30.0);
    EXPECT_EQ(info.exit_code, 0) << info.describe();
}

TEST(ViewerSession, PanelsDrawInEveryView) {
    REQUIRE_XVFB();
    const fs::path dir = test::temp_dir("viewer_session_panels");
    // A window wide enough for the panel to start open; every view, training running and stopped. One
    // sample per film (lavapipe traces a 480x270 frame in seconds with validation on).
    const RunResult r = run_view(dir, "set max_spp 1\nframes 2\nset view split\nframes 2\nset view difference\nframes 2\ncompare\n"
                                      "set view flip\nframes 2\ncompare\nframes 1\n"
                                      "set train_backend cpu\nset train_steps 100000\nset train_nodes 31\n"
                                      "set train_batch 256\nset train_hash_log2 10\nset train_snapshot 5\n"
                                      "train start\nframes 6\ntrain pause\nframes 2\ntrain resume\nframes 2\n"
                                      "train stop\nframes 2\nscreenshot ui.png\nreport r.json\n",
                                 {"--model", tiny_model().string()}, 300.0, true);
    expect_clean(r);
    const json j = read_json(dir / "r.json");
    EXPECT_EQ(j["training"]["state"], "stopped");
    EXPECT_EQ(j["width"], 480);
    const Image ui = load_image((dir / "ui.png").string());
    EXPECT_EQ(ui.width, 480);
}

} // namespace
} // namespace nbvh
