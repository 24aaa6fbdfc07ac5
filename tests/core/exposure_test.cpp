// Automatic exposure (nbvh render --exposure auto): the key luminance goes to AUTO_EXPOSURE_KEY, the
// brightest percent stays below the tone map's shoulder, black and non-finite pixels do not count.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/core/exposure.h"

namespace nbvh {
namespace {

Image grey(int w, int h, float v) {
    Image img(w, h, 4, v);
    for (size_t i = 0; i < img.pixel_count(); ++i) img.data[i * 4 + 3] = 1.0f;
    return img;
}

TEST(AutoExposure, MapsTheKeyToMiddleGrey) {
    for (float v : {1.0e-4f, 0.01f, 0.3f, 5.0f}) {
        const AutoExposure a = auto_exposure(grey(16, 16, v));
        EXPECT_NEAR(a.key, v, 1e-3f * v);
        EXPECT_NEAR(a.stops, std::log2(AUTO_EXPOSURE_KEY / v), 1e-3f) << v;
        EXPECT_EQ(a.lit_pixels, 256u);
    }
}

TEST(AutoExposure, BlackBackgroundAndNonFinitePixelsDoNotCount) {
    Image img = grey(10, 10, 0.0f);
    for (int x = 0; x < 10; ++x) img.at(x, 0)[0] = img.at(x, 0)[1] = img.at(x, 0)[2] = 0.03f;
    img.at(0, 5)[1] = NAN;
    img.at(1, 5)[1] = INFINITY;
    const AutoExposure a = auto_exposure(img);
    EXPECT_EQ(a.lit_pixels, 10u);
    EXPECT_NEAR(a.stops, std::log2(AUTO_EXPOSURE_KEY / 0.03f), 1e-3f);
    EXPECT_EQ(auto_exposure(grey(4, 4, 0.0f)).stops, 0.0f) << "nothing lit: no exposure";
}

TEST(AutoExposure, BrightestPercentIsNotBlownOut) {
    // A dim image with 5 % of very bright pixels (a lamp in view): the key alone would push the lamp far
    // past white; the exposure is limited so the 99th percentile stays at AUTO_EXPOSURE_BRIGHT.
    Image img = grey(20, 20, 0.01f);
    for (int i = 0; i < 20; ++i) img.at(i, 0)[0] = img.at(i, 0)[1] = img.at(i, 0)[2] = 100.0f;
    const AutoExposure a = auto_exposure(img);
    EXPECT_NEAR(a.bright, 100.0f, 1e-3f);
    EXPECT_NEAR(a.stops, std::log2(AUTO_EXPOSURE_BRIGHT / 100.0f), 1e-3f);
    EXPECT_LT(a.stops, std::log2(AUTO_EXPOSURE_KEY / 0.01f));
}

} // namespace
} // namespace nbvh
