// The quasi-random sampler of the path tracer (shaders/shared/sampling.h nb_qmc_2d: shuffled,
// Owen-scrambled Sobol, Burley 2020) on the CPU: the first two Sobol dimensions, nets at every
// power-of-two prefix and block (the property the variance reduction rests on), uniform and
// independent across seeds, a lower error than independent numbers on integrands a path tracer meets
// (smooth, and with an edge), and sample reuse (nb_sample_reuse) keeping a chosen subset a net.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "shaders/shared/sampling.h"

namespace {

TEST(QmcSampler, SobolDimensionsAreTheReferenceOnes) {
    // Dimension 0: van der Corput; dimension 1: Pascal's matrix mod 2 (Joe & Kuo's second dimension).
    const float vdc[8] = {0.0f, 0.5f, 0.25f, 0.75f, 0.125f, 0.625f, 0.375f, 0.875f};
    const float d1[8] = {0.0f, 0.5f, 0.75f, 0.25f, 0.625f, 0.125f, 0.375f, 0.875f};
    for (uint i = 0; i < 8; ++i) {
        EXPECT_EQ(double(nb_reverse_bits(i)) / 4294967296.0, vdc[i]) << i;
        EXPECT_EQ(double(nb_sobol_dim1(i)) / 4294967296.0, d1[i]) << i;
    }
    EXPECT_EQ(nb_reverse_bits(0x12345678u), 0x1E6A2C48u);
    // The butterfly form against the textbook one: XOR of the direction numbers v_1 = 1/2,
    // v_{k+1} = v_k ^ (v_k >> 1) of the index's set bits.
    for (uint i : {9u, 255u, 256u, 0x12345678u, 0x80000001u, 0xFFFFFFFFu}) {
        uint r = 0u, v = 0x80000000u;
        for (uint j = i; j != 0u; j >>= 1u, v ^= v >> 1u) r ^= (j & 1u) ? v : 0u;
        EXPECT_EQ(nb_sobol_dim1(i), r) << i;
    }
    // nb_qmc_2d is the scrambled pair of the shuffled index (the reversals that cancel left out).
    const uint seed = 4242u, i = nb_owen_scramble(37u, seed);
    const vec2 u = nb_qmc_2d(37u, seed);
    const uint sx = nb_pcg_hash(seed ^ 0xA3C59AC3u), sy = nb_pcg_hash(seed ^ 0x3C6EF372u);
    EXPECT_EQ(uint(double(u.x) * 16777216.0), nb_owen_scramble(nb_reverse_bits(i), sx) >> 8);
    EXPECT_EQ(uint(double(u.y) * 16777216.0), nb_owen_scramble(nb_sobol_dim1(i), sy) >> 8);
}

TEST(QmcSampler, OwenScrambleKeepsTheHigherBitsPrefix) {
    // Bit j of the result depends only on bits above it: values sharing their top k bits stay together.
    for (uint seed : {1u, 77u, 0xABCDEF01u})
        for (uint x : {0x12345678u, 0x80000000u, 0xFFFFFFFFu}) {
            const uint a = nb_owen_scramble(x, seed), b = nb_owen_scramble(x ^ 0x0000FFFFu, seed);
            EXPECT_EQ(a >> 16, b >> 16) << x << " " << seed;
        }
}

// Every power-of-two block of 2^m consecutive samples (from a multiple of 2^m) is a (0, m, 2)-net:
// each elementary box 2^-k x 2^-(m-k) holds exactly one point.
void expect_net(uint first, uint m, uint seed) {
    const uint n = 1u << m;
    for (uint k = 0; k <= m; ++k) {
        std::vector<int> cells(n, 0);
        for (uint i = first; i < first + n; ++i) {
            const vec2 u = nb_qmc_2d(i, seed);
            ASSERT_GE(u.x, 0.0f);
            ASSERT_LT(u.x, 1.0f);
            ASSERT_GE(u.y, 0.0f);
            ASSERT_LT(u.y, 1.0f);
            const uint cx = uint(u.x * float(1u << k)), cy = uint(u.y * float(1u << (m - k)));
            ++cells[cx * (1u << (m - k)) + cy];
        }
        for (uint c = 0; c < n; ++c)
            ASSERT_EQ(cells[c], 1) << "block at " << first << " of 2^" << m << ", boxes 2^-" << k << " x 2^-"
                                   << (m - k) << ", seed " << seed;
    }
}

TEST(QmcSampler, EveryPowerOfTwoBlockIsANet) {
    for (uint seed : {0u, 1u, 12345u, nb_qmc_dim_seed(nb_qmc_pixel_seed(640u * 360u + 17u, 0u), 3u, 4u)})
        for (uint m = 0; m <= 10; ++m)
            for (uint first : {0u, 1u << m, 5u << m}) expect_net(first, m, seed);
}

// Sample reuse (shade.comp's next-event strategy): the points of a 2^m net whose x chose [lo, lo + p)
// with p = 2^-j and lo a multiple of it, x rescaled by nb_sample_reuse, are a (0, m - j, 2)-net.
TEST(QmcSampler, SampleReuseKeepsTheChosenPointsANet) {
    const uint m = 10;
    for (uint seed : {3u, 999u, nb_qmc_dim_seed(nb_qmc_pixel_seed(77u, 5u), 1u, 2u)})
        for (uint j : {1u, 2u})
            for (uint part = 0; part < (1u << j); ++part) {
                const float p = 1.0f / float(1u << j), lo = float(part) * p;
                std::vector<vec2> pts;
                for (uint i = 0; i < (1u << m); ++i) {
                    const vec2 u = nb_qmc_2d(i, seed);
                    if (u.x >= lo && u.x < lo + p) pts.push_back(vec2(nb_sample_reuse(u.x, lo, p), u.y));
                }
                const uint mm = m - j, n = 1u << mm;
                ASSERT_EQ(pts.size(), n);
                for (uint k = 0; k <= mm; ++k) {
                    std::vector<int> cells(n, 0);
                    for (const vec2& q : pts) {
                        ASSERT_GE(q.x, 0.0f);
                        ASSERT_LT(q.x, 1.0f);
                        ++cells[uint(q.x * float(1u << k)) * (1u << (mm - k)) + uint(q.y * float(1u << (mm - k)))];
                    }
                    for (uint c = 0; c < n; ++c)
                        ASSERT_EQ(cells[c], 1) << "seed " << seed << ", p 2^-" << j << ", part " << part << ", k " << k;
                }
            }
}

// Its hard cases: the interval's ends, a tiny or rounding-prone interval, the largest float below 1.
TEST(QmcSampler, SampleReuseStaysInTheUnitInterval) {
    const float below_one = 0.99999994f;
    EXPECT_EQ(nb_sample_reuse(0.25f, 0.25f, 0.5f), 0.0f);
    EXPECT_LT(nb_sample_reuse(std::nextafter(0.75f, 0.0f), 0.25f, 0.5f), 1.0f);
    EXPECT_LT(nb_sample_reuse(below_one, 0.0f, 1.0f), 1.0f);
    EXPECT_EQ(nb_sample_reuse(below_one, 0.0f, 1.0f), below_one); // one strategy: the number unchanged
    EXPECT_LT(nb_sample_reuse(below_one, 2.0f / 3.0f, 1.0f / 3.0f), 1.0f);
    const float tiny = 1.0e-7f; // an option of probability 1e-7: u in [0.5, 0.5 + 1e-7)
    for (float u = 0.5f; u < 0.5f + tiny; u = std::nextafter(u, 1.0f)) {
        const float r = nb_sample_reuse(u, 0.5f, tiny);
        ASSERT_TRUE(std::isfinite(r));
        ASSERT_GE(r, 0.0f);
        ASSERT_LT(r, 1.0f);
    }
    for (float lo : {0.1f, 1.0f / 3.0f, 0.7f})
        for (float p : {0.2f, 1.0f / 7.0f, 0.3f}) {
            if (lo + p > 1.0f) continue;
            const float hi = std::nextafter(lo + p, 0.0f); // the last u that still chose [lo, lo + p)
            EXPECT_LT(nb_sample_reuse(hi, lo, p), 1.0f) << lo << " " << p;
            EXPECT_GE(nb_sample_reuse(lo, lo, p), 0.0f) << lo << " " << p;
        }
}

TEST(QmcSampler, SeedsGiveUniformIndependentSequences) {
    const uint n = 4096;
    const uint s1 = nb_qmc_dim_seed(nb_qmc_pixel_seed(10u, 0u), 0u, 1u);
    const uint s2 = nb_qmc_dim_seed(nb_qmc_pixel_seed(10u, 0u), 0u, 2u); // the next pair of the same path
    const uint s3 = nb_qmc_dim_seed(nb_qmc_pixel_seed(11u, 0u), 0u, 1u); // the same pair of the next pixel
    double mean = 0.0, c12 = 0.0, c13 = 0.0, cxy = 0.0;
    for (uint i = 0; i < n; ++i) {
        const vec2 a = nb_qmc_2d(i, s1), b = nb_qmc_2d(i, s2), c = nb_qmc_2d(i, s3);
        mean += a.x + a.y;
        c12 += (a.x - 0.5) * (b.x - 0.5);
        c13 += (a.y - 0.5) * (c.y - 0.5);
        cxy += (a.x - 0.5) * (a.y - 0.5);
    }
    const double var = 1.0 / 12.0;
    EXPECT_NEAR(mean / (2 * n), 0.5, 1e-3);
    // Independent scrambles: correlations of order 1/sqrt(n) = 0.016 (a shared unshuffled index would
    // give correlations far larger, of either sign).
    EXPECT_LT(std::abs(c12 / n / var), 0.06);
    EXPECT_LT(std::abs(c13 / n / var), 0.06);
    EXPECT_LT(std::abs(cxy / n / var), 0.06);
    EXPECT_NE(nb_qmc_2d(3u, s1).x, nb_qmc_2d(3u, s2).x);
}

// Mean squared error over many pixels (seeds) of 256-sample estimates of a 2D integral.
template <class F> double mse(F f, double exact, bool qmc) {
    const uint spp = 256, pixels = 400;
    double sum = 0.0;
    for (uint p = 0; p < pixels; ++p) {
        const uint seed = nb_qmc_dim_seed(nb_qmc_pixel_seed(p, 9u), 0u, 2u);
        uint rng = nb_rng_init(p, 0u, 9u);
        double est = 0.0;
        for (uint i = 0; i < spp; ++i) {
            vec2 u = qmc ? nb_qmc_2d(i, seed) : vec2(0.0f);
            if (!qmc) {
                u.x = nb_rng_next(rng);
                u.y = nb_rng_next(rng);
            }
            est += f(u.x, u.y);
        }
        const double e = est / spp - exact;
        sum += e * e;
    }
    return sum / pixels;
}

TEST(QmcSampler, ErrorFallsFasterThanWithIndependentNumbers) {
    // A cosine-weighted irradiance-like term (smooth) and a shadow edge (a disc: visibility).
    auto smooth = [](float x, float y) {
        return double(std::sqrt(1.0f - x) * (1.0f + std::cos(6.2831853f * y)));
    };
    auto disc = [](float x, float y) {
        return (x - 0.4) * (x - 0.4) + (y - 0.55) * (y - 0.55) < 0.09 ? 1.0 : 0.0;
    };
    const double smooth_exact = 2.0 / 3.0, disc_exact = 3.14159265358979 * 0.09;
    const double s_random = mse(smooth, smooth_exact, false), s_qmc = mse(smooth, smooth_exact, true);
    const double d_random = mse(disc, disc_exact, false), d_qmc = mse(disc, disc_exact, true);
    // Independent numbers: variance / 256. Scrambled nets: O(n^-3) for smooth integrands, O(n^-1.5) with
    // an edge; at 256 samples at least 500x and 8x less error here (measured: ~2900x and ~14x).
    EXPECT_LT(s_qmc * 500.0, s_random) << s_qmc << " vs " << s_random;
    EXPECT_LT(d_qmc * 8.0, d_random) << d_qmc << " vs " << d_random;
    // Unbiased: the mean error is within its standard error (checked through the MSE staying finite
    // and the means agreeing below).
    double m_qmc = 0.0;
    for (uint p = 0; p < 200; ++p)
        for (uint i = 0; i < 64; ++i) {
            const vec2 u = nb_qmc_2d(i, nb_qmc_dim_seed(nb_qmc_pixel_seed(p, 1u), 1u, 1u));
            m_qmc += disc(u.x, u.y);
        }
    EXPECT_NEAR(m_qmc / (200 * 64), disc_exact, 0.005);
}

} // namespace
