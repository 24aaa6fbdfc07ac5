// The default hash size of nbvh train (trainer/compact_hash.h): the grid stays at most a fifth of the
// geometry it replaces, within [2^12, the backend's maximum].
#include <gtest/gtest.h>

#include "engine/neural/model_file.h"
#include "trainer/compact_hash.h"

using namespace nbvh;

TEST(CompactHash, GridIsAtMostAFifthOfTheGeometry) {
    const NeuralConfig cfg;
    // Grid sizes of the paper's layout (8 levels x 4 fp16 features, base 8, scale 2): 2^18 -> 10.3 MiB.
    EXPECT_EQ(grid_bytes(cfg, 18), 10784768u);
    EXPECT_EQ(grid_bytes(cfg, 17), 5541888u);
    // Chess (473k triangles, 252k vertices: ~42 MiB of mesh + BLAS): 2^17 (5.3 MiB), not 2^18 (10.3 MiB).
    EXPECT_EQ(compact_hash_log2(cfg, mesh_and_blas_bytes(473432, 252060), 18), 17u);
    // The Stanford dragon (871k triangles, 438k vertices: ~77 MiB): the paper's 2^18.
    EXPECT_EQ(compact_hash_log2(cfg, mesh_and_blas_bytes(871414, 437645), 18), 18u);
    // The bunny (~70k triangles, ~35k vertices: ~6 MiB): 2^14 (0.8 MiB); the CPU maximum is respected.
    EXPECT_EQ(compact_hash_log2(cfg, mesh_and_blas_bytes(69451, 34834), 18), 14u);
    EXPECT_EQ(compact_hash_log2(cfg, mesh_and_blas_bytes(871414, 437645), 15), 15u);
    // Every choice above the floor satisfies the ratio; tiny meshes get the floor; a floor above the
    // maximum yields the maximum.
    for (uint64_t tris : {10ull, 1000ull, 100000ull, 10000000ull}) {
        const uint64_t geo = mesh_and_blas_bytes(tris, tris / 2);
        const uint32_t t = compact_hash_log2(cfg, geo, 18);
        EXPECT_GE(t, COMPACT_HASH_MIN_LOG2);
        EXPECT_LE(t, 18u);
        if (t > COMPACT_HASH_MIN_LOG2) { EXPECT_LE(grid_bytes(cfg, t) * COMPACT_HASH_RATIO, geo) << tris; }
        if (t < 18u) { EXPECT_GT(grid_bytes(cfg, t + 1) * COMPACT_HASH_RATIO, geo) << tris; }
    }
    EXPECT_EQ(compact_hash_log2(cfg, 10, 8), 8u);
}
