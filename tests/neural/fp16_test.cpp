// fp16 conversion pins (round to nearest even, subnormals, inf, NaN).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "engine/neural/fp16.h"

using namespace nbvh;

TEST(Fp16, PinnedValues) {
    EXPECT_EQ(float_to_half_bits(0.0f), 0x0000u);
    EXPECT_EQ(float_to_half_bits(-0.0f), 0x8000u);
    EXPECT_EQ(float_to_half_bits(1.0f), 0x3C00u);
    EXPECT_EQ(float_to_half_bits(-2.0f), 0xC000u);
    EXPECT_EQ(float_to_half_bits(0.5f), 0x3800u);
    EXPECT_EQ(float_to_half_bits(1.0f / 3.0f), 0x3555u); // 0.333251953125
    EXPECT_EQ(half_bits_to_float(0x3555u), 0.333251953125f);
    EXPECT_EQ(float_to_half_bits(65504.0f), 0x7BFFu);     // max finite
    EXPECT_EQ(float_to_half_bits(65519.0f), 0x7BFFu);     // below the rounding midpoint
    EXPECT_EQ(float_to_half_bits(65520.0f), 0x7C00u);     // midpoint rounds to even = inf
    EXPECT_EQ(float_to_half_bits(1e6f), 0x7C00u);
    EXPECT_EQ(float_to_half_bits(-1e6f), 0xFC00u);
    EXPECT_EQ(float_to_half_bits(6.103515625e-05f), 0x0400u); // min normal 2^-14
    EXPECT_EQ(float_to_half_bits(5.9604644775390625e-08f), 0x0001u); // min subnormal 2^-24
    EXPECT_EQ(float_to_half_bits(2.98023223876953125e-08f), 0x0000u); // 2^-25: tie -> even (0)
    EXPECT_EQ(float_to_half_bits(3.0e-08f), 0x0001u);                 // just above the tie
    EXPECT_EQ(float_to_half_bits(8.940696716308594e-08f), 0x0002u);   // 1.5 * 2^-24: tie -> even (2)
    EXPECT_EQ(float_to_half_bits(1e-10f), 0x0000u);
    EXPECT_EQ(half_bits_to_float(0x0001u), 5.9604644775390625e-08f);
    EXPECT_EQ(half_bits_to_float(0x03FFu), 6.097555160522461e-05f); // max subnormal
    EXPECT_EQ(float_to_half_bits(6.097555160522461e-05f), 0x03FFu);
    // ties to even in the normal range: 1 + 2^-11 is halfway between 1 and 1 + 2^-10
    EXPECT_EQ(float_to_half_bits(1.0f + 0.00048828125f), 0x3C00u);
    EXPECT_EQ(float_to_half_bits(1.0f + 3.0f * 0.00048828125f), 0x3C02u);
}

TEST(Fp16, InfNan) {
    const float inf = std::numeric_limits<float>::infinity();
    EXPECT_EQ(float_to_half_bits(inf), 0x7C00u);
    EXPECT_EQ(float_to_half_bits(-inf), 0xFC00u);
    EXPECT_TRUE(std::isinf(half_bits_to_float(0x7C00u)));
    const uint16_t n = float_to_half_bits(std::nanf(""));
    EXPECT_EQ(n & 0x7C00u, 0x7C00u);
    EXPECT_NE(n & 0x03FFu, 0u); // stays NaN, not inf
    EXPECT_TRUE(std::isnan(half_bits_to_float(n)));
    EXPECT_TRUE(std::isnan(half_bits_to_float(0x7E00u)));
}

TEST(Fp16, RoundTripAllHalves) {
    // Every finite half converts to float and back unchanged.
    for (uint32_t h = 0; h < 0x10000u; ++h) {
        if ((h & 0x7C00u) == 0x7C00u) continue;
        ASSERT_EQ(float_to_half_bits(half_bits_to_float(uint16_t(h))), h) << h;
    }
}

TEST(Fp16, RoundingIsNearest) {
    // For random floats in the half range, the chosen half is at least as close as its neighbours.
    uint32_t s = 12345u;
    for (int i = 0; i < 20000; ++i) {
        s = s * 1664525u + 1013904223u;
        const float f = (float(s >> 8) / float(1u << 24) - 0.5f) * 2.0f * std::ldexp(1.0f, int(s % 30u) - 20);
        const uint16_t h = float_to_half_bits(f);
        const double err = std::fabs(double(half_bits_to_float(h)) - f);
        const double up = std::fabs(double(half_bits_to_float(uint16_t(h + 1))) - f);
        const double dn = (h & 0x7FFFu) ? std::fabs(double(half_bits_to_float(uint16_t(h - 1))) - f) : 1e30;
        ASSERT_LE(err, up) << f;
        ASSERT_LE(err, dn) << f;
    }
}
