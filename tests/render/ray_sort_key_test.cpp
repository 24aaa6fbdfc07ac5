// The ray order's key (shared/wavefront_gpu.h nb_rs_key, passes/ray_sort.comp and shade.comp): 4 levels
// per axis of the unit direction in the top 6 bits, the Morton code of the origin's cell of an 8^3 grid
// over the world bounds below. Hard cases: origins on cell faces, on and outside the bounds (clamped to
// the border cells), NaN and infinite coordinates, -0, zero, unnormalised and NaN directions, level
// borders, zero-extent (flat) bounds, tiny and huge scenes far from 0.
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

TEST(RaySortKey, DirectionLevelsAndMortonCellOfTheOrigin) {
    const vec3 lo(-2.0f, 0.0f, 5.0f), hi(6.0f, 1.0f, 9.0f);
    const float value[4] = {-0.75f, -0.25f, 0.25f, 0.75f}; // one per level
    std::set<uint> seen;
    uint dirs = 0;
    for (uint dir = 0; dir < 64; ++dir) {
        const uint l[3] = {dir & 3u, (dir >> 2u) & 3u, (dir >> 4u) & 3u};
        auto small = [](uint v) { return v == 1u || v == 2u; };
        if (small(l[0]) && small(l[1]) && small(l[2])) continue; // no unit vector has 3 components under 0.5
        ++dirs;
        const vec3 d = vec3(value[l[0]], value[l[1]], value[l[2]]) * 3.0f; // not unit: the key normalises
        for (uint z = 0; z < 8; ++z)
            for (uint y = 0; y < 8; ++y)
                for (uint x = 0; x < 8; ++x) {
                    const vec3 o = lo + (hi - lo) * (vec3(float(x), float(y), float(z)) + 0.5f) / 8.0f;
                    const uint key = nb_rs_key(o, d, lo, hi);
                    ASSERT_LT(key, NB_RS_BINS);
                    EXPECT_EQ(key >> 9u, dir);
                    EXPECT_EQ(cell_of(key), uvec3(x, y, z));
                    seen.insert(key);
                }
    }
    EXPECT_EQ(dirs, 56u);
    EXPECT_EQ(seen.size(), size_t(dirs) * 512u) << "every reachable (direction, cell) has its own bin";
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
    // Direction levels: -0 counts as non-negative (level 2), the unit axes hit the end levels, level
    // borders go up; zero, infinite and NaN directions are all level 2 (defined, in range).
    const uint level2 = 2u | (2u << 2u) | (2u << 4u);
    EXPECT_EQ(nb_rs_key(vec3(0.5f), vec3(-0.0f, 1.0f, 0.0f), lo, hi) >> 9u, 2u | (3u << 2u) | (2u << 4u));
    EXPECT_EQ(nb_rs_key(vec3(0.5f), vec3(-1.0f, 0.0f, 0.0f), lo, hi) >> 9u, 0u | (2u << 2u) | (2u << 4u));
    EXPECT_EQ(nb_rs_key(vec3(0.5f), vec3(0.0f, 0.0f, 1.0f), lo, hi) >> 9u, 2u | (2u << 2u) | (3u << 4u));
    EXPECT_EQ(nb_rs_dir_level(-0.5f), 1u);
    EXPECT_EQ(nb_rs_dir_level(0.5f), 3u);
    EXPECT_EQ(nb_rs_dir_level(-1.0000001f), 0u);
    EXPECT_EQ(nb_rs_dir_level(1.0000001f), 3u);
    EXPECT_EQ(nb_rs_dir_level(nan), 2u);
    for (const vec3 d : {vec3(0.0f), vec3(nan), vec3(inf, 0.0f, 0.0f), vec3(-0.0f, 1.0f, nan)})
        EXPECT_EQ(nb_rs_key(vec3(0.5f), d, lo, hi) >> 9u, level2);
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
