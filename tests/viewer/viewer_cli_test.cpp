// `nbvh view` end to end: headless under Xvfb (lavapipe renders into an X11 swapchain) with the
// validation layer on, and the one-line error without a display.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "engine/core/image.h"
#include "tests/support/test_support.h"

namespace nbvh {
namespace {

std::string read_file(const std::filesystem::path& p) {
    std::ifstream f(p);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

// Runs a shell command; returns its exit status (-1 when it did not exit normally).
int run(const std::string& command) {
    const int r = std::system(command.c_str());
    return WIFEXITED(r) ? WEXITSTATUS(r) : -1;
}

bool have_xvfb_run() { return run("command -v xvfb-run > /dev/null 2>&1") == 0; }

TEST(ViewerCli, HeadlessScreenshotUnderXvfb) {
    if (!have_xvfb_run()) GTEST_SKIP() << "xvfb-run not installed (Debian: xvfb)";
    const std::filesystem::path dir = test::temp_dir("viewer_headless");
    const std::filesystem::path png = dir / "out.png", log = dir / "log.txt";
    const std::string cmd = "NBVH_VALIDATION=1 xvfb-run -a " + std::string(NBVH_EXE) +
                            " view default --device cpu --width 160 --height 90 --frames 4 --screenshot " +
                            png.string() + " > " + log.string() + " 2>&1";
    const int rc = run(cmd);
    const std::string text = read_file(log);
    ASSERT_EQ(rc, 0) << text;
    EXPECT_NE(text.find("view: Vulkan validation on"), std::string::npos) << text; // the layer was active
    EXPECT_EQ(text.find("vulkan validation:"), std::string::npos) << text;         // and silent
    ASSERT_TRUE(std::filesystem::exists(png)) << text;
    const Image img = load_image(png.string());
    EXPECT_EQ(img.width, 160);
    EXPECT_EQ(img.height, 90);
    // Not uniform: the film (sky, ground, knot) has a spread of values.
    double lo = 1e9, hi = -1e9;
    for (size_t i = 0; i < img.pixel_count(); ++i) {
        const float* p = img.data.data() + i * 4;
        const double l = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
        lo = std::min(lo, l);
        hi = std::max(hi, l);
    }
    EXPECT_GT(hi - lo, 0.1) << "screenshot is (nearly) uniform: " << lo << " .. " << hi;
}

// --env none as in nbvh render (app/render_args.h choose_environment): only the scene's own lights, so the
// default scene's sky is black; without it the default sky shows above the horizon.
TEST(ViewerCli, EnvNoneKeepsOnlyTheScenesLights) {
    if (!have_xvfb_run()) GTEST_SKIP() << "xvfb-run not installed (Debian: xvfb)";
    const std::filesystem::path dir = test::temp_dir("viewer_env_none");
    auto top_row_luminance = [&](const std::string& extra, const std::string& name) {
        const std::filesystem::path png = dir / (name + ".png"), log = dir / (name + ".txt");
        const int rc = run("xvfb-run -a " + std::string(NBVH_EXE) + " view default --device cpu --width 96 --height 54 " +
                           "--frames 2 --hide-ui --screenshot " + png.string() + extra + " > " + log.string() + " 2>&1");
        EXPECT_EQ(rc, 0) << read_file(log);
        const Image img = load_image(png.string());
        double sum = 0.0;
        for (int x = 0; x < img.width; ++x) {
            const float* p = img.at(x, 0);
            sum += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
        }
        return sum / std::max(1, img.width);
    };
    EXPECT_GT(top_row_luminance("", "sky"), 0.05) << "the default sky";
    EXPECT_EQ(top_row_luminance(" --env none", "none"), 0.0) << "no environment: a black background";
}

// --subdivide L as for nbvh render: a model trained on the subdivided scene is shown with the same L (the
// view's scene has 4^L times the triangles) and refused without it, one line naming the option.
TEST(ViewerCli, SubdivideAsForRender) {
    if (!have_xvfb_run()) GTEST_SKIP() << "xvfb-run not installed (Debian: xvfb)";
    const std::filesystem::path dir = test::temp_dir("viewer_subdivide");
    const std::filesystem::path model = dir / "m.nbvh", png = dir / "out.png", log = dir / "log.txt";
    ASSERT_EQ(run(std::string(NBVH_EXE) +
                  " train default --backend cpu --steps 2 --batch 64 --nodes 8 --lods 1 " +
                  "--subdivide 1 --out " + model.string() + " > " + log.string() + " 2>&1"),
              0)
        << read_file(log);
    const std::string view =
        "xvfb-run -a " + std::string(NBVH_EXE) + " view default --device cpu --width 64 " +
        "--height 36 --frames 1 --hide-ui --model " + model.string() + " --screenshot " + png.string();
    EXPECT_NE(run(view + " > " + log.string() + " 2>&1"), 0);
    std::string text = read_file(log);
    EXPECT_NE(text.find("nbvh: error:"), std::string::npos) << text;
    EXPECT_NE(text.find("--subdivide"), std::string::npos) << text;
    EXPECT_FALSE(std::filesystem::exists(png));
    ASSERT_EQ(run(view + " --subdivide 1 > " + log.string() + " 2>&1"), 0) << read_file(log);
    text = read_file(log);
    EXPECT_NE(text.find("--subdivide 1:"), std::string::npos) << "the subdivision's log line: " << text;
    EXPECT_TRUE(std::filesystem::exists(png)) << text;
    EXPECT_NE(run("env -u DISPLAY " + std::string(NBVH_EXE) + " view default --subdivide 5 > " +
                  log.string() + " 2>&1"),
              0);
    EXPECT_NE(read_file(log).find("--subdivide"), std::string::npos) << read_file(log);
}

TEST(ViewerCli, NoDisplayIsOneClearLine) {
    const std::filesystem::path dir = test::temp_dir("viewer_no_display");
    const std::filesystem::path log = dir / "log.txt";
    const int rc = run("env -u DISPLAY -u WAYLAND_DISPLAY " + std::string(NBVH_EXE) + " view default > " +
                       log.string() + " 2>&1");
    const std::string text = read_file(log);
    EXPECT_NE(rc, 0);
    EXPECT_EQ(text, "nbvh: error: no display available (set DISPLAY or use nbvh render)\n");
}

TEST(ViewerCli, ScreenshotMustBePng) {
    const int rc = run("env -u DISPLAY " + std::string(NBVH_EXE) + " view default --screenshot out.jpg > /dev/null 2>&1");
    EXPECT_NE(rc, 0);
}

} // namespace
} // namespace nbvh
