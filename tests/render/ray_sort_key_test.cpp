// The ray order's key (shared/wavefront_gpu.h nb_rs_key, passes/ray_sort.comp and shade.comp): direction
// octant in the top 3 bits, the Morton code of the origin's cell of an 8^3 grid over the world bounds
// below. Hard cases: origins on cell faces, on and outside the bounds (clamped to the border cells), NaN
// and infinite coordinates, -0 directions, zero-extent (flat) bounds, tiny and huge scenes far from 0.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>

#include "shaders/shared/wavefront_gpu.h"

namespace {

uvec3 cell_of(uint key) {
    uvec3 c(0u);
    for (uint b = 0; b < 3; ++b) {
        c.x |= ((key >> (3u * b)) & 1u) << b;
        c.y |= ((key >> (3u * b + 1u)) & 1u) << b;
        c.z |= ((key >> (3u * b + 2u)) & 1u) << b;
    }
    return c;
}

TEST(RaySortKey, OctantAndMortonCellOfTheOrigin) {
    const vec3 lo(-2.0f, 0.0f, 5.0f), hi(6.0f, 1.0f, 9.0f);
    std::set<uint> seen;
    for (uint oct = 0; oct < 8; ++oct) {
        const vec3 d((oct & 1u) ? -1.0f : 1.0f, (oct & 2u) ? -0.5f : 0.5f, (oct & 4u) ? -2.0f : 2.0f);
        for (uint z = 0; z < 8; ++z)
            for (uint y = 0; y < 8; ++y)
                for (uint x = 0; x < 8; ++x) {
                    const vec3 o = lo + (hi - lo) * (vec3(float(x), float(y), float(z)) + 0.5f) / 8.0f;
                    const uint key = nb_rs_key(o, d, lo, hi);
                    ASSERT_LT(key, NB_RS_BINS);
                    EXPECT_EQ(key >> 9u, oct);
                    EXPECT_EQ(cell_of(key), uvec3(x, y, z));
                    seen.insert(key);
                }
    }
    EXPECT_EQ(seen.size(), size_t(NB_RS_BINS)) << "every bin is some (octant, cell)'s";
    // Consecutive keys within a 2x2x2 block are neighbouring cells (Morton order).
    for (uint k = 0; k < 512; k += 8)
        for (uint j = 1; j < 8; ++j) {
            const uvec3 a = cell_of(k), b = cell_of(k + j);
            EXPECT_LE(std::max({b.x - a.x, b.y - a.y, b.z - a.z}), 1u);
        }
}

TEST(RaySortKey, BordersNonFiniteAndExtremeScenesStayInRange) {
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    const vec3 lo(0.0f), hi(1.0f);
    // Outside the bounds: the border cells; on the upper face: the last cell.
    EXPECT_EQ(cell_of(nb_rs_key(vec3(-5.0f, 0.5f, 2.0f), vec3(1.0f), lo, hi)), uvec3(0u, 4u, 7u));
    EXPECT_EQ(cell_of(nb_rs_key(vec3(1.0f), vec3(1.0f), lo, hi)), uvec3(7u));
    // NaN and infinite coordinates: defined cells (NaN -> 0), the key in range.
    EXPECT_EQ(cell_of(nb_rs_key(vec3(nan, 0.5f, -inf), vec3(1.0f), lo, hi)), uvec3(0u, 4u, 0u));
    EXPECT_EQ(cell_of(nb_rs_key(vec3(inf), vec3(1.0f), lo, hi)), uvec3(7u));
    EXPECT_LT(nb_rs_key(vec3(nan), vec3(nan), lo, hi), NB_RS_BINS);
    // -0 and NaN directions count as positive (not < 0).
    EXPECT_EQ(nb_rs_key(vec3(0.5f), vec3(-0.0f, 1.0f, nan), lo, hi) >> 9u, 0u);
    // Flat bounds (a single plane) and tiny / huge scenes far from the origin.
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-0.5f, 1.5f);
    for (float scale : {1e-4f, 1.0f, 1e4f})
        for (vec3 offset : {vec3(0.0f), vec3(3e4f, -2e4f, 1e4f)}) {
            const vec3 blo = offset, bhi = offset + vec3(scale, 0.0f, 2.0f * scale); // flat in y
            for (int i = 0; i < 5000; ++i) {
                const vec3 o = blo + vec3(u(rng), u(rng), u(rng)) * vec3(scale, scale, 2.0f * scale);
                const uint key = nb_rs_key(o, vec3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f), blo, bhi);
                ASSERT_LT(key, NB_RS_BINS) << scale;
            }
        }
}

} // namespace
