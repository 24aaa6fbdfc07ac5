// Walk culling of the N-BVH (lib/neural_traverse.glsl): the renderer grows the node boxes with
// nb_neural_cull_bounds (shared/neural_gpu.h) so that no leaf interval (nb_neural_leaf_interval: the leaf
// dilated about its centre) starts before its ancestor's box entry. A leaf entered before the node would
// be culled when the walk narrows its limit to the round's worst kept key, and lost for good (later rounds
// start behind that key). A resumed walk also culls by the ray's last queued key from below (its g_tmin
// raised to it), which needs the exit side: no leaf interval ends after its ancestor's box exit, so a
// leaf whose key is at or above the last one is never behind a culled node. Hard cases: leaves flush
// with the node's faces, thin and flat leaves, rays grazing a face, origins inside the dilation margin,
// tiny (1e-4) and huge (1e4) boxes, 3e6 offsets.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "shaders/shared/neural_gpu.h"

namespace {

struct Box {
    vec3 lo, hi;
};

vec3 lerp3(const Box& b, vec3 f) { return b.lo + (b.hi - b.lo) * f; }

TEST(NeuralCullBounds, NodeIntervalContainsEveryDilatedLeafInterval) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    const float scales[] = {1.0e-4f, 1.0f, 1.0e4f};
    const vec3 offsets[] = {vec3(0.0f), vec3(3.0e6f, -2.0e6f, 1.0e6f)};
    uint64_t leaf_hits = 0, lost_with_plain_boxes = 0, exit_lost_with_plain_boxes = 0;
    for (float scale : scales)
        for (vec3 offset : offsets) {
            if (scale < 1.0f && offset.x != 0.0f) continue; // 1e-4 boxes 3e6 away are below float spacing
            for (int trial = 0; trial < 4000; ++trial) {
                Box node{offset, offset + vec3(scale) * vec3(0.5f + u01(rng), 0.5f + u01(rng), 0.5f + u01(rng))};
                // A leaf inside the node, flush with one or more faces half the time, thin or flat at times.
                vec3 a(u01(rng), u01(rng), u01(rng)), b(u01(rng), u01(rng), u01(rng));
                for (int k = 0; k < 3; ++k) {
                    if (a[k] > b[k]) std::swap(a[k], b[k]);
                    if (trial % 2 == 0) { a[k] = k == trial % 3 ? 0.0f : a[k]; b[k] = k == (trial / 2) % 3 ? 1.0f : b[k]; }
                    if (trial % 7 == 0 && k == 1) b[k] = a[k]; // flat
                }
                const Box leaf{lerp3(node, a), lerp3(node, b)};
                vec3 clo = node.lo, chi = node.hi;
                nb_neural_cull_bounds(clo, chi);
                // Rays from outside the node through the leaf's faces, grazing (origin in a face's plane),
                // and from inside the dilation margin outward.
                for (int r = 0; r < 8; ++r) {
                    vec3 target = lerp3(leaf, vec3(u01(rng), u01(rng), u01(rng)));
                    vec3 dir = normalize(vec3(u01(rng) - 0.5f, u01(rng) - 0.5f, u01(rng) - 0.5f));
                    vec3 org = target - dir * (scale * (r < 4 ? 3.0f : 1.0e-5f));
                    if (r == 6) { org[r % 3] = leaf.lo[r % 3]; dir[r % 3] = 0.0f; }
                    if (r == 7) { org = leaf.hi + (leaf.hi - leaf.lo) * 4.0e-6f; dir = normalize(leaf.hi - leaf.lo + vec3(1e-3f * scale)); }
                    const vec3 inv = nb_safe_inv_dir(dir);
                    float le, lx;
                    if (!nb_neural_leaf_interval(org, inv, leaf.lo, leaf.hi, le, lx)) continue;
                    for (float tmin : {0.0f, -NB_INF}) {
                        if (!(lx > tmin)) continue;
                        ++leaf_hits;
                        const float key = std::max(le, tmin);
                        float ne;
                        // The walk's node test at the narrowest limit that still admits the leaf: its key.
                        ASSERT_TRUE(nb_intersect_aabb(org, inv, clo, chi, tmin, key, ne))
                            << "scale " << scale << " trial " << trial << " ray " << r;
                        EXPECT_LE(ne, key);
                        // The resumed walk's node test when the leaf's key equals the last queued key
                        // (the walk's tmin raised to it; a leaf of the same key can still follow it in
                        // key order): the node must be entered at exactly that distance.
                        ASSERT_TRUE(nb_intersect_aabb(org, inv, clo, chi, key, key, ne))
                            << "exit side: scale " << scale << " trial " << trial << " ray " << r;
                        float nn, nx;
                        ASSERT_TRUE(nb_intersect_aabb_interval(org, inv, clo, chi, -NB_INF, NB_INF, nn, nx));
                        EXPECT_GE(nx, lx) << "a leaf interval ends after its node's box";
                        // Negative control: the node's own box (what the GPU layout stored before).
                        float pe, pn, px;
                        if (!nb_intersect_aabb(org, inv, node.lo, node.hi, tmin, key, pe)) ++lost_with_plain_boxes;
                        if (nb_intersect_aabb_interval(org, inv, node.lo, node.hi, -NB_INF, NB_INF, pn, px) && px < lx)
                            ++exit_lost_with_plain_boxes;
                    }
                }
            }
        }
    EXPECT_GT(leaf_hits, 50000u);
    EXPECT_GT(lost_with_plain_boxes, 0u) << "the hard cases must include leaves the plain node box would lose";
    EXPECT_GT(exit_lost_with_plain_boxes, 0u) << "and leaves ending after the plain node box's exit";
    std::printf("%llu leaf intervals, %llu of them lost by the plain node box (%llu ending after its exit)\n",
                (unsigned long long)leaf_hits, (unsigned long long)lost_with_plain_boxes,
                (unsigned long long)exit_lost_with_plain_boxes);
}

TEST(NeuralCullBounds, GrowthIsSmallAndEmptyBoxesStayEmpty) {
    vec3 lo(1.0f, 2.0f, 3.0f), hi(2.0f, 2.0f, 5.0f); // flat in y
    nb_neural_cull_bounds(lo, hi);
    EXPECT_LT(lo.y, 2.0f);
    EXPECT_GT(hi.y, 2.0f);
    EXPECT_NEAR(hi.x - lo.x, 1.0f, 1.0e-4f);
    vec3 elo(NB_INF), ehi(-NB_INF); // an absent child's box
    nb_neural_cull_bounds(elo, ehi);
    EXPECT_GT(elo.x, ehi.x);
}

} // namespace
