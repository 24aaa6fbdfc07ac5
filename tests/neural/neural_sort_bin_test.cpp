// The leaf-binned query order's key (shared/neural_gpu.h nb_nl_sort_bin, lib/neural_bindings.glsl):
// bins are the Morton codes of a 16^3 grid over the encoding box, so that consecutive bins are
// neighbouring cells and the query pass walks the asset in space-filling order. Hard cases: leaf
// centres on cell faces, on the box's faces and outside it (clamped to the border cells, never past
// the last bin), flat (zero-extent) leaves, NaN-free tiny (1e-4) and huge (1e4) boxes far from the origin.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <set>

#include "shaders/shared/neural_gpu.h"

namespace {

GpuEncodingBox box_of(vec3 lo, vec3 hi) { return nb_make_encoding_box(lo, hi); }

// The cell coordinates back from a bin (x in bits 0, 3, 6, 9; y shifted by 1; z by 2).
uvec3 cell_of_bin(uint bin) {
    uvec3 c(0u);
    for (uint b = 0; b < NB_NL_SORT_AXIS_BITS; ++b) {
        c.x |= ((bin >> (3u * b)) & 1u) << b;
        c.y |= ((bin >> (3u * b + 1u)) & 1u) << b;
        c.z |= ((bin >> (3u * b + 2u)) & 1u) << b;
    }
    return c;
}

TEST(NeuralSortBin, MortonCodeOfTheCellOfTheLeafCentre) {
    EXPECT_EQ(nb_nl_spread4(0xFu), 0x249u);
    EXPECT_EQ(nb_nl_spread4(0x5u), 0x041u);
    EXPECT_EQ(nb_nl_spread4(0x10u), 0u) << "only the low 4 bits";
    const vec3 lo(-3.0f, 1.0f, 2.0f), hi(5.0f, 2.0f, 10.0f);
    const GpuEncodingBox box = box_of(lo, hi);
    std::set<uint> seen;
    for (uint z = 0; z < 16; ++z)
        for (uint y = 0; y < 16; ++y)
            for (uint x = 0; x < 16; ++x) {
                // A small leaf at the centre of cell (x, y, z) of the encoding grid.
                const vec3 f = (vec3(float(x), float(y), float(z)) + 0.5f) / 16.0f;
                const vec3 c = box.center + (f - 0.5f) * box.extent;
                const vec3 h = box.extent * 1e-3f;
                const uint bin = nb_nl_sort_bin(box, c - h, c + h);
                ASSERT_LT(bin, NB_NL_SORT_BINS);
                EXPECT_EQ(cell_of_bin(bin), uvec3(x, y, z));
                seen.insert(bin);
            }
    EXPECT_EQ(seen.size(), size_t(NB_NL_SORT_BINS)) << "every bin is some cell's";
    // Consecutive bins of one 2x2x2 block are neighbouring cells (space-filling order).
    for (uint b = 0; b < NB_NL_SORT_BINS; b += 8) {
        const uvec3 c0 = cell_of_bin(b);
        for (uint j = 1; j < 8; ++j) {
            const uvec3 c = cell_of_bin(b + j);
            EXPECT_LE(std::max({c.x - c0.x, c.y - c0.y, c.z - c0.z}), 1u);
        }
    }
}

TEST(NeuralSortBin, BordersFlatLeavesAndExtremeScalesStayInRange) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-0.5f, 1.5f); // centres inside and outside the box
    uint64_t outside = 0;
    for (float scale : {1.0e-4f, 1.0f, 1.0e4f})
        for (vec3 offset : {vec3(0.0f), vec3(3.0e4f, -2.0e4f, 1.0e4f)}) {
            const vec3 lo = offset, hi = offset + vec3(scale) * vec3(1.0f, 0.25f, 2.0f);
            const GpuEncodingBox box = box_of(lo, hi);
            for (int i = 0; i < 20000; ++i) {
                vec3 f(u(rng), u(rng), u(rng));
                if (i % 5 == 0) f = glm::floor(f * 16.0f) / 16.0f; // centre exactly on a cell face
                if (i % 7 == 0) f.x = i % 2 ? 0.0f : 1.0f;           // on the box's faces
                const vec3 c = lo + f * (hi - lo);
                vec3 a = c, b = c;
                if (i % 3 != 0) { // flat leaves otherwise
                    a -= (hi - lo) * 0.01f;
                    b += (hi - lo) * 0.01f;
                }
                const uint bin = nb_nl_sort_bin(box, a, b);
                ASSERT_LT(bin, NB_NL_SORT_BINS) << "scale " << scale << " f " << f.x << " " << f.y << " " << f.z;
                const vec3 e = nb_encode_point(box, (a + b) * 0.5f);
                const bool inside = e.x >= 0.0f && e.x < 1.0f && e.y >= 0.0f && e.y < 1.0f && e.z >= 0.0f && e.z < 1.0f;
                if (!inside) {
                    ++outside;
                    // Clamped to the border cell of each axis that is outside.
                    const uvec3 cell = cell_of_bin(bin);
                    for (int k = 0; k < 3; ++k) {
                        if (e[k] < 0.0f) EXPECT_EQ(cell[k], 0u);
                        if (e[k] >= 1.0f) EXPECT_EQ(cell[k], 15u);
                    }
                }
            }
        }
    EXPECT_GT(outside, 1000u) << "the test draws centres outside the box";
}

} // namespace
