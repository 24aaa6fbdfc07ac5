// scripts/bench/panel.py, which makes the crop figures of results/ (results/scenes, results/perf): two
// lavapipe renders side by side, cropped and scaled, the panel's size; bad arguments as one-line errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "tests/cli/run_nbvh.h"
#include "tests/support/test_support.h"

namespace fs = std::filesystem;
using nbvh::test::run_nbvh;

namespace {

// Width and height from a PNG's IHDR chunk (big-endian words at bytes 16 and 20); 0 x 0 if not a PNG.
std::pair<uint32_t, uint32_t> png_size(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    unsigned char b[24] = {};
    f.read(reinterpret_cast<char*>(b), 24);
    if (!f || std::string(reinterpret_cast<char*>(b), 8) != std::string("\x89PNG\r\n\x1a\n", 8))
        return {0, 0};
    auto word = [&](int o) {
        return uint32_t(b[o]) << 24 | uint32_t(b[o + 1]) << 16 | uint32_t(b[o + 2]) << 8 | b[o + 3];
    };
    return {word(16), word(20)};
}

TEST(PanelScript, CropsSideBySideWithLabels) {
    const fs::path python = "/usr/bin/python3"; // Debian's, with python3-pil (python3-matplotlib needs it)
    if (nbvh::test::run_command(python, {"-c", "import PIL"}, 60.0).exit_code != 0)
        GTEST_SKIP()
            << "python3-pil is not installed (scripts/setup.sh installs python3-matplotlib): not checked";
    const fs::path dir = nbvh::test::temp_dir("panel_script");
    for (const char* seed : {"1", "2"}) { // two images of one size
        const auto r = run_nbvh({"render", "default", "--classical", "--device", "cpu", "--width", "40",
                                 "--height", "24", "--spp", "1", "--seed", seed, "--out",
                                 (dir / (std::string("s") + seed + ".png")).string()},
                                120.0);
        ASSERT_EQ(r.exit_code, 0) << r.describe();
    }
    const std::string script = (nbvh::test::source_dir() / "scripts/bench/panel.py").string();
    const std::string a = "a=" + (dir / "s1.png").string(), b = "b=" + (dir / "s2.png").string();
    const fs::path out = dir / "panel.png";
    const auto r = nbvh::test::run_command(
        python, {script, out.string(), "--crop", "10,4,20,12", "--scale", "2", a, b}, 60.0);
    ASSERT_EQ(r.exit_code, 0) << r.describe();
    const auto [w, h] = png_size(out);
    EXPECT_EQ(w, 2u * 20 * 2) << "two crops of 20 pixels, scaled 2x, side by side";
    EXPECT_EQ(h, 12u * 2 + 16) << "the crop's 12 rows scaled 2x under a 16-pixel label bar";

    // Bad arguments: one line on stderr, a non-zero exit, nothing written.
    const fs::path none = dir / "none.png";
    const std::vector<std::vector<std::string>> bad = {
        {script, none.string(), "--crop", "30,4,20,12", a, b},          // leaves the 40-pixel-wide image
        {script, none.string(), "--crop", "1,2,3", a},                  // not X,Y,W,H
        {script, none.string(), "a=" + (dir / "missing.png").string()}, // no such image
        {script, none.string(), "--scale", "0", a},
        {script, (dir / "s1.png").string(), a, b}, // would replace an input
    };
    for (const auto& args : bad) {
        const auto e = nbvh::test::run_command(python, args, 60.0);
        EXPECT_NE(e.exit_code, 0) << e.describe();
        EXPECT_NE(e.err.find("panel.py"), std::string::npos) << e.describe();
        EXPECT_EQ(e.err.find("Traceback"), std::string::npos) << e.describe();
    }
    EXPECT_FALSE(fs::exists(none));
    EXPECT_GT(png_size(dir / "s1.png").first, 0u) << "the input is untouched";
}

} // namespace
