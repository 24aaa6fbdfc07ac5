#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>

#include "engine/core/error.h"
#include "engine/core/image.h"
#include "tests/support/test_support.h"

using namespace nbvh;

TEST(Image, SrgbRoundTripAndKnownValues) {
    EXPECT_FLOAT_EQ(srgb_to_linear(0.0f), 0.0f);
    EXPECT_FLOAT_EQ(srgb_to_linear(1.0f), 1.0f);
    EXPECT_NEAR(srgb_to_linear(0.5f), 0.214041f, 1e-6f);
    for (int v = 0; v <= 255; ++v) {
        const float c = float(v) / 255.0f;
        EXPECT_NEAR(linear_to_srgb(srgb_to_linear(c)), c, 1e-5f);
    }
}

TEST(Image, PngRoundTripKeepsBytes) {
    const auto dir = test::temp_dir("image_png");
    Image img(5, 3, 4);
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 5; ++x) {
            float* p = img.at(x, y);
            p[0] = srgb_to_linear(float(x * 50) / 255.0f);
            p[1] = srgb_to_linear(float(y * 100) / 255.0f);
            p[2] = 0.25f;
            p[3] = 1.0f;
        }
    const std::string path = (dir / "a.png").string();
    save_png(path, img);
    const Image back = load_image(path);
    ASSERT_EQ(back.width, 5);
    ASSERT_EQ(back.height, 3);
    ASSERT_EQ(back.channels, 4);
    for (size_t i = 0; i < img.data.size(); ++i) EXPECT_NEAR(back.data[i], img.data[i], 2e-3f) << i;
    EXPECT_EQ(back.at(2, 0)[0], srgb_to_linear(100.0f / 255.0f)); // exact 8-bit decode
}

TEST(Image, ExrRoundTripIsExactInFloat) {
    const auto dir = test::temp_dir("image_exr");
    Image img(4, 2, 4);
    for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = float(i) * 0.37f + 0.001f;
    const std::string path = (dir / "a.exr").string();
    save_exr(path, img);
    const Image back = load_image(path);
    ASSERT_EQ(back.width, 4);
    ASSERT_EQ(back.height, 2);
    for (size_t i = 0; i < img.data.size(); ++i) EXPECT_EQ(back.data[i], img.data[i]) << i;
}

TEST(Image, ToneMapsAndExposure) {
    Image img(1, 1, 3);
    img.data = {4.0f, 0.5f, 0.0f};
    PngEncode enc;
    enc.exposure = -1.0f; // halves: 2.0 -> clamped to 255, 0.25 -> sRGB 137
    const auto px = to_srgb8(img, enc);
    ASSERT_EQ(px.size(), 3u);
    EXPECT_EQ(px[0], 255);
    EXPECT_EQ(px[1], uint8_t(std::lround(linear_to_srgb(0.25f) * 255.0f)));
    EXPECT_EQ(px[2], 0);
    float rgb[3] = {1e6f, 0.0f, 1.0f};
    tone_map_rgb(ToneMap::aces, rgb);
    EXPECT_NEAR(rgb[0], 0.9036f / 0.8748f, 1e-3f); // limit k0/k3 (>1, clamped when encoding)
    EXPECT_EQ(rgb[1], 0.0f);
    EXPECT_THROW(parse_tone_map("filmic"), Error);
}

TEST(Image, NonFiniteCountingAndSanitizing) {
    Image img(2, 1, 3);
    img.data = {1.0f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                -std::numeric_limits<float>::infinity(), 0.5f, 0.0f};
    EXPECT_EQ(count_non_finite(img), 3u);
    const auto px = to_srgb8(img, {}); // must not crash or produce garbage
    EXPECT_EQ(px[1], 0);
    EXPECT_EQ(px[2], 255);
    EXPECT_EQ(sanitize_non_finite(img), 3u);
    EXPECT_EQ(count_non_finite(img), 0u);
    EXPECT_EQ(img.data[1], 0.0f);
    EXPECT_EQ(img.data[2], 65504.0f);
    EXPECT_EQ(img.data[3], 0.0f);
}

TEST(Image, BadFilesThrowClearErrors) {
    const auto dir = test::temp_dir("image_bad");
    EXPECT_THROW(load_image((dir / "missing.png").string()), Error);
    const std::string junk = (dir / "junk.png").string();
    std::ofstream(junk) << "this is not a png";
    EXPECT_THROW(load_image(junk), Error);
    const std::string junk_exr = (dir / "junk.exr").string();
    std::ofstream(junk_exr) << "this is not an exr";
    EXPECT_THROW(load_image(junk_exr), Error);
    const std::string txt = (dir / "a.txt").string();
    std::ofstream(txt) << "x";
    EXPECT_THROW(load_image(txt), Error);
}

TEST(Image, ConvertChannels) {
    Image img(1, 1, 3);
    img.data = {0.1f, 0.2f, 0.3f};
    const Image rgba = convert_channels(img, 4);
    EXPECT_EQ(rgba.data, (std::vector<float>{0.1f, 0.2f, 0.3f, 1.0f}));
    const Image rgb = convert_channels(rgba, 3);
    EXPECT_EQ(rgb.data, img.data);
}
