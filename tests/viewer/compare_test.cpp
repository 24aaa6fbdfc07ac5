// The compare views' pure parts (app/viewer/compare.h, imgui_layer.h): the difference and FLIP images
// of two display images, the display encoding (the bytes of nbvh render's PNGs), and where the film
// lies in the window (the split line's mapping). No device needed.
#include <gtest/gtest.h>

#include <cmath>

#include "app/viewer/compare.h"
#include "app/viewer/imgui_layer.h"
#include "engine/core/flip.h"

namespace nbvh::viewer {
namespace {

Image gradient(int w, int h) {
    Image img(w, h, 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c)
                img.data[(size_t(y) * w + x) * 3 + size_t(c)] = float(x + y + c) / float(w + h + 3);
    return img;
}

uint32_t channel(uint32_t px, int c) { return (px >> (8 * c)) & 0xFFu; }

TEST(ViewerCompare, IdenticalImagesAreBlackAndZero) {
    const Image a = gradient(48, 32);
    for (ViewMode mode : {ViewMode::difference, ViewMode::flip}) {
        const CompareResult r = compare_images(a, a, mode, 8.0f);
        EXPECT_EQ(r.width, 48u);
        EXPECT_EQ(r.height, 32u);
        EXPECT_EQ(r.mode, mode);
        EXPECT_DOUBLE_EQ(r.flip_mean, 0.0);
        EXPECT_DOUBLE_EQ(r.mean_abs_difference, 0.0);
        const std::vector<uint8_t> zero_heat = flip_heatmap_rgb8(flip_ldr(a, a));
        for (size_t i = 0; i < r.rgba8.size(); ++i) {
            EXPECT_EQ(r.rgba8[i] >> 24, 255u);
            for (int c = 0; c < 3; ++c)
                EXPECT_EQ(channel(r.rgba8[i], c), mode == ViewMode::flip ? zero_heat[i * 3 + size_t(c)] : 0u);
        }
    }
}

TEST(ViewerCompare, DifferenceAndFlipLightUpWhereTheImagesDiffer) {
    const Image ref = gradient(64, 40);
    Image test = ref;
    // A 10x10 block brighter by 0.2 (linear) in the test image.
    for (int y = 10; y < 20; ++y)
        for (int x = 30; x < 40; ++x)
            for (int c = 0; c < 3; ++c) test.data[(size_t(y) * 64 + x) * 3 + size_t(c)] += 0.2f;
    const CompareResult d = compare_images(test, ref, ViewMode::difference, 4.0f);
    double inside = 0.0, outside = 0.0;
    for (int y = 0; y < 40; ++y)
        for (int x = 0; x < 64; ++x) {
            const uint32_t px = d.rgba8[size_t(y) * 64 + x];
            const bool in = y >= 10 && y < 20 && x >= 30 && x < 40;
            // |srgb(a) - srgb(b)| x gain, as the window shows it.
            const size_t i = (size_t(y) * 64 + x) * 3;
            const float want = std::min(1.0f, 4.0f * std::fabs(linear_to_srgb(test.data[i]) - linear_to_srgb(ref.data[i])));
            EXPECT_NEAR(double(channel(px, 0)), double(want) * 255.0, 0.51);
            (in ? inside : outside) += channel(px, 0);
        }
    EXPECT_GT(inside / 100.0, 60.0);
    EXPECT_EQ(outside, 0.0);
    EXPECT_GT(d.mean_abs_difference, 0.0);

    const CompareResult f = compare_images(test, ref, ViewMode::flip, 1.0f);
    EXPECT_NEAR(f.flip_mean, flip_ldr(ref, test).mean, 1e-7); // reference first, as nbvh flip REF TEST
    EXPECT_GT(f.flip_mean, 0.0);
    const std::vector<uint8_t> heat = flip_heatmap_rgb8(flip_ldr(ref, test));
    for (size_t i = 0; i < f.rgba8.size(); ++i)
        for (int c = 0; c < 3; ++c) ASSERT_EQ(channel(f.rgba8[i], c), heat[i * 3 + size_t(c)]);
}

TEST(ViewerCompare, PngPixelsAreThePngBytesDecoded) {
    Image film(5, 2, 4);
    for (size_t i = 0; i < film.data.size(); ++i) film.data[i] = float(i % 7) * 0.37f;
    const Image px = as_png_pixels(film, 1.0f);
    PngEncode enc;
    enc.exposure = 1.0f;
    enc.tone_map = ToneMap::aces;
    int channels = 0;
    const std::vector<uint8_t> bytes = to_srgb8(film, enc, &channels);
    ASSERT_EQ(px.channels, 3);
    for (size_t i = 0; i < film.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c)
            EXPECT_FLOAT_EQ(px.data[i * 3 + size_t(c)], srgb_to_linear(float(bytes[i * size_t(channels) + size_t(c)]) / 255.0f));
}

TEST(ViewerCompare, FilmRectIsThePresentersFit) {
    const FilmRect same = film_rect(160, 90, 160, 90);
    EXPECT_FLOAT_EQ(same.x, 0.0f);
    EXPECT_FLOAT_EQ(same.width, 160.0f);
    const FilmRect wide = film_rect(200, 90, 160, 90); // pillarbox: 20 px each side
    EXPECT_FLOAT_EQ(wide.x, 20.0f);
    EXPECT_FLOAT_EQ(wide.y, 0.0f);
    EXPECT_FLOAT_EQ(wide.width, 160.0f);
    const FilmRect tall = film_rect(160, 180, 160, 90); // letterbox
    EXPECT_FLOAT_EQ(tall.y, 45.0f);
    EXPECT_FLOAT_EQ(tall.height, 90.0f);
    EXPECT_FLOAT_EQ(film_rect(10, 10, 0, 0).width, 0.0f);
}

} // namespace
} // namespace nbvh::viewer
