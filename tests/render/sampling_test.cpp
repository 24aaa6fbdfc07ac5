// shaders/shared/sampling.h on the CPU: pdfs integrate to one, VNDF samples match nb_ggx_pdf, the
// environment mapping round-trips.
#include <gtest/gtest.h>

#include <cmath>

#include "shaders/shared/sampling.h"

namespace {

// Uniform hemisphere estimate of the integral of the GGX reflection pdf over the upper hemisphere must
// equal the fraction of VNDF samples whose reflection stays above the horizon (the rest end the path).
TEST(Sampling, GgxPdfIntegratesToTheValidSampleFraction) {
    for (float alpha : {0.1f, 0.5f, 1.0f}) {
        const vec3 wo = normalize(vec3(0.3f, 0.0f, 1.0f));
        uint rng = nb_rng_init(1u, 2u, 3u);
        double sum = 0.0;
        const int n = 400000;
        for (int i = 0; i < n; ++i) {
            const float u1 = nb_rng_next(rng), u2 = nb_rng_next(rng);
            const float z = u1, r = std::sqrt(std::max(0.0f, 1.0f - z * z)), phi = 2.0f * NB_PI * u2;
            const vec3 wi(r * std::cos(phi), r * std::sin(phi), z);
            const vec3 h = normalize(wo + wi);
            sum += nb_ggx_pdf(wo.z, h.z, alpha) * 2.0 * NB_PI; // / uniform pdf 1/(2 pi)
        }
        int valid = 0;
        for (int i = 0; i < n; ++i) {
            const vec3 h = nb_ggx_sample_vndf(wo, alpha, nb_rng_next(rng), nb_rng_next(rng));
            valid += (2.0f * dot(wo, h) * h - wo).z > 0.0f;
        }
        EXPECT_NEAR(sum / n, double(valid) / n, 0.02) << "alpha " << alpha;
        EXPECT_LE(sum / n, 1.01);
    }
}

// Directions sampled with nb_ggx_sample_vndf have the density nb_ggx_pdf: E[g / pdf] = integral of g.
TEST(Sampling, VndfSamplesFollowGgxPdf) {
    const float alpha = 0.5f;
    const vec3 wo = normalize(vec3(0.2f, -0.1f, 1.0f));
    uint rng = nb_rng_init(4u, 5u, 6u);
    double est = 0.0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
        const vec3 h = nb_ggx_sample_vndf(wo, alpha, nb_rng_next(rng), nb_rng_next(rng));
        const vec3 wi = 2.0f * dot(wo, h) * h - wo;
        if (wi.z <= 0.0f) continue;
        est += double(wi.z) / nb_ggx_pdf(wo.z, h.z, alpha); // integral of cos over the hemisphere = pi
    }
    EXPECT_NEAR(est / n, NB_PI, 0.05 * NB_PI);
}

TEST(Sampling, CosineSamplesAreUnitAndUpper) {
    uint rng = nb_rng_init(7u, 8u, 9u);
    for (int i = 0; i < 1000; ++i) {
        const vec3 d = nb_sample_cosine(nb_rng_next(rng), nb_rng_next(rng));
        EXPECT_NEAR(length(d), 1.0f, 1e-4f);
        EXPECT_GE(d.z, 0.0f);
    }
}

TEST(Sampling, EnvironmentMappingRoundTrips) {
    for (float rot : {0.0f, 1.3f}) {
        for (float v : {0.1f, 0.5f, 0.9f})
            for (float u : {0.05f, 0.3f, 0.77f}) {
                const vec3 d = nb_env_uv_to_dir(vec2(u, v), rot);
                const vec2 uv = nb_env_dir_to_uv(d, rot);
                EXPECT_NEAR(uv.x, u, 1e-4f);
                EXPECT_NEAR(uv.y, v, 1e-4f);
            }
    }
    // Official convention: -z is the centre of the map (u = 0.5), +y the top row.
    EXPECT_NEAR(nb_env_dir_to_uv(vec3(0, 0, -1), 0.0f).x, 0.5f, 1e-6f);
    EXPECT_NEAR(nb_env_dir_to_uv(vec3(0, 1, 0), 0.0f).y, 0.0f, 1e-6f);
}

// The environment's bilinear footprint (shared/sampling.h, used by lib/env.glsl): texel centres at
// half-integers, u wrapping across the seam, v clamped at the poles.
TEST(Sampling, EnvironmentFootprintWrapsUAndClampsV) {
    uvec2 lo, hi;
    vec2 f;
    nb_env_bilinear_footprint(vec2(0.5f, 0.5f), 4, 2, lo, hi, f); // the edge between columns 1 and 2
    EXPECT_EQ(lo, uvec2(1, 0));
    EXPECT_EQ(hi, uvec2(2, 1));
    EXPECT_NEAR(f.x, 0.5f, 1e-6f);
    EXPECT_NEAR(f.y, 0.5f, 1e-6f);
    nb_env_bilinear_footprint(vec2(0.01f, 0.1f), 4, 2, lo, hi, f); // left of column 0's centre: wraps to 3
    EXPECT_EQ(lo, uvec2(3, 0));
    EXPECT_EQ(hi, uvec2(0, 0)) << "v above the first row's centre clamps to row 0";
    EXPECT_NEAR(f.x, 0.54f, 1e-5f);
    nb_env_bilinear_footprint(vec2(0.99f, 0.99f), 4, 2, lo, hi, f); // right of column 3's centre: wraps to 0
    EXPECT_EQ(lo, uvec2(3, 1));
    EXPECT_EQ(hi, uvec2(0, 1)) << "v below the last row's centre clamps to the last row";
    EXPECT_NEAR(f.x, 0.46f, 1e-5f);
}

TEST(Sampling, RngIsUniformAndSeedDependent) {
    uint a = nb_rng_init(10u, 0u, 1u), b = nb_rng_init(10u, 0u, 2u);
    EXPECT_NE(a, b);
    double mean = 0.0;
    for (int i = 0; i < 100000; ++i) {
        const float x = nb_rng_next(a);
        ASSERT_GE(x, 0.0f);
        ASSERT_LT(x, 1.0f);
        mean += x;
    }
    EXPECT_NEAR(mean / 100000, 0.5, 0.01);
}

} // namespace
