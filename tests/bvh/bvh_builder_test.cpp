// Builder invariants on random and degenerate primitive sets, bounds padding and the GPU layout.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <cstring>
#include <random>

#include "engine/bvh/aabb_ops.h"
#include "engine/bvh/bvh.h"
#include "engine/bvh/mesh_bvh.h"
#include "test_geometry.h"

namespace nbvh {
namespace {

// Checks every structural guarantee of build_bvh (bvh.h). Returns the number of kept primitives.
void check_invariants(const Bvh& bvh, const std::vector<Aabb>& prims, const BvhBuildOptions& o) {
    size_t valid = 0;
    for (const Aabb& b : prims) valid += is_valid(b);
    ASSERT_EQ(bvh.prim_indices.size(), valid);
    if (valid == 0) {
        EXPECT_TRUE(bvh.empty());
        return;
    }
    const uint32_t max_leaf = std::clamp<uint32_t>(o.max_leaf_size, 1u, NB_LEAF_MAX_COUNT);
    std::vector<int> seen_prim(prims.size(), 0), covered(bvh.prim_indices.size(), 0);
    for (uint32_t id : bvh.prim_indices) {
        ASSERT_LT(id, prims.size());
        ASSERT_TRUE(is_valid(prims[id]));
        ++seen_prim[id];
    }
    for (size_t i = 0; i < prims.size(); ++i) ASSERT_EQ(seen_prim[i], is_valid(prims[i]) ? 1 : 0);
    ASSERT_EQ(bvh.nodes[0].parent, BVH_INVALID);
    ASSERT_EQ(bvh.nodes[0].depth, 0u);
    for (size_t i = 0; i < bvh.nodes.size(); ++i) {
        const BvhNode& n = bvh.nodes[i];
        ASSERT_TRUE(is_valid(n.bounds));
        ASSERT_LT(n.depth, NB_BVH_MAX_DEPTH);
        if (n.is_leaf()) {
            ASSERT_LE(n.count, max_leaf);
            ASSERT_LE(size_t(n.first) + n.count, bvh.prim_indices.size());
            for (uint32_t k = n.first; k < n.first + n.count; ++k) {
                ++covered[k];
                ASSERT_TRUE(contains(n.bounds, prims[bvh.prim_indices[k]]));
            }
        } else {
            ASSERT_EQ(n.right, n.left + 1);
            ASSERT_GT(n.left, i);
            ASSERT_LT(n.right, bvh.nodes.size());
            for (uint32_t c : {n.left, n.right}) {
                ASSERT_EQ(bvh.nodes[c].parent, i);
                ASSERT_EQ(bvh.nodes[c].depth, n.depth + 1);
                ASSERT_TRUE(contains(n.bounds, bvh.nodes[c].bounds));
            }
        }
    }
    for (int c : covered) ASSERT_EQ(c, 1); // leaves partition prim_indices
    ASSERT_LT(bvh.max_depth(), NB_BVH_MAX_DEPTH);
}

std::vector<Aabb> triangle_bounds(const std::vector<glm::vec3>& v) {
    std::vector<Aabb> out(v.size() / 3);
    for (size_t t = 0; t < out.size(); ++t)
        for (int k = 0; k < 3; ++k) out[t].grow(v[3 * t + k]);
    return out;
}

TEST(BvhBuilder, EmptyAndSingle) {
    std::vector<Aabb> none;
    Bvh e = build_bvh(none);
    EXPECT_TRUE(e.empty());
    EXPECT_TRUE(to_gpu_layout(e).empty());

    std::vector<Aabb> one(1);
    one[0].grow(glm::vec3(1.0f, 2.0f, 3.0f));
    Bvh s = build_bvh(one);
    check_invariants(s, one, {});
    ASSERT_EQ(s.nodes.size(), 1u);
    auto g = to_gpu_layout(s);
    ASSERT_EQ(g.size(), 1u);
    EXPECT_TRUE(nb_is_leaf(g[0].left));
    EXPECT_EQ(nb_leaf_first(g[0].left), 0u);
    EXPECT_EQ(nb_leaf_count(g[0].left), 1u);
    EXPECT_EQ(g[0].right, NB_CHILD_NONE);
    EXPECT_GT(g[0].rmin.x, g[0].rmax.x); // empty bounds: no ray enters
}

TEST(BvhBuilder, RandomSetsAllOptions) {
    std::mt19937 rng(1);
    for (uint32_t n : {2u, 3u, 17u, 1000u, 20000u}) {
        auto prims = triangle_bounds(test::random_soup(rng, n, 10.0f, 0.5f));
        for (uint32_t leaf : {0u, 1u, 4u, 16u, 100u}) {
            BvhBuildOptions o;
            o.max_leaf_size = leaf;
            o.bin_count = leaf == 100u ? 1u : 16u; // clamped to 2 bins
            check_invariants(build_bvh(prims, o), prims, o);
        }
    }
}

TEST(BvhBuilder, DegenerateSets) {
    std::vector<std::vector<Aabb>> sets;
    // All identical points.
    sets.emplace_back(1000);
    for (Aabb& b : sets.back()) b.grow(glm::vec3(0.5f, -2.0f, 3.0f));
    // All identical boxes, and identical centroids with different sizes.
    sets.emplace_back(300);
    for (size_t i = 0; i < sets.back().size(); ++i) {
        float s = float(i % 7) + 1.0f;
        sets.back()[i].grow(glm::vec3(-s));
        sets.back()[i].grow(glm::vec3(s));
    }
    // Flat along z (all z = 0), and a line along x.
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    sets.emplace_back(2000);
    for (Aabb& b : sets.back()) {
        glm::vec3 c(u(rng), u(rng), 0.0f);
        b.grow(c);
        b.grow(c + glm::vec3(0.01f, 0.01f, 0.0f));
    }
    sets.emplace_back(2000);
    for (Aabb& b : sets.back()) b.grow(glm::vec3(u(rng), 0.0f, 0.0f));
    // Non-finite, empty and huge bounds mixed with valid ones.
    sets.emplace_back();
    for (int i = 0; i < 500; ++i) {
        Aabb b;
        switch (i % 5) {
        case 0: b.grow(glm::vec3(std::nanf(""), 0.0f, 0.0f)); break;
        case 1: b.lo = glm::vec3(-INFINITY); b.hi = glm::vec3(1.0f); break;
        case 2: break; // empty
        case 3: b.grow(glm::vec3(-FLT_MAX)); b.grow(glm::vec3(FLT_MAX)); break;
        default: b.grow(glm::vec3(u(rng), u(rng), u(rng)) * 1e38f); break;
        }
        sets.back().push_back(b);
    }
    // Exponentially spaced primitives: SAH would build a chain; the depth bound must hold.
    sets.emplace_back();
    for (int i = 0; i < 3000; ++i) {
        Aabb b;
        b.grow(glm::vec3(std::pow(1.02f, float(i)), 0.0f, 0.0f));
        sets.back().push_back(b);
    }
    // Tiny and huge scales far from the origin.
    sets.emplace_back(triangle_bounds(test::random_soup(rng, 3000, 1e-3f, 1e-4f, glm::vec3(1e5f))));
    sets.emplace_back(triangle_bounds(test::random_soup(rng, 3000, 1e5f, 1e4f, glm::vec3(-1e5f))));
    for (size_t s = 0; s < sets.size(); ++s) {
        for (uint32_t leaf : {1u, 4u}) {
            BvhBuildOptions o;
            o.max_leaf_size = leaf;
            SCOPED_TRACE("set " + std::to_string(s) + " leaf " + std::to_string(leaf));
            check_invariants(build_bvh(sets[s], o), sets[s], o);
            o.min_node_extent = BBOX_REGULARISATION;
            check_invariants(build_bvh(sets[s], o), sets[s], o);
        }
    }
}

TEST(BvhBuilder, PaddingRemovesFlatNodes) {
    std::mt19937 rng(4);
    for (glm::vec3 offset : {glm::vec3(0.0f), glm::vec3(1e5f, -1e5f, 3e4f)}) {
        // A flat (z = const) point set: every node is flat on z before padding.
        std::vector<Aabb> prims(500);
        std::uniform_real_distribution<float> u(-1.0f, 1.0f);
        for (Aabb& b : prims) b.grow(offset + glm::vec3(u(rng), u(rng), 0.0f));
        BvhBuildOptions o;
        o.min_node_extent = BBOX_REGULARISATION;
        Bvh bvh = build_bvh(prims, o);
        check_invariants(bvh, prims, o);
        for (const BvhNode& n : bvh.nodes) {
            glm::vec3 e = n.bounds.hi - n.bounds.lo;
            for (int a = 0; a < 3; ++a) {
                EXPECT_GT(e[a], 0.0f);
                if (offset == glm::vec3(0.0f)) {
                    EXPECT_GE(e[a], 0.99f * BBOX_REGULARISATION);
                }
            }
        }
    }
    // pad_degenerate keeps finite, non-empty bounds even at the float limit.
    Aabb huge;
    huge.grow(glm::vec3(FLT_MAX, -FLT_MAX, 0.0f));
    Aabb p = pad_degenerate(huge);
    EXPECT_TRUE(is_valid(p));
    EXPECT_TRUE(contains(p, huge));
}

TEST(BvhBuilder, TooDeepInputStaysWithinStack) {
    // Nested boxes around one point: centroids identical, the median fallback keeps depth ~log2(n).
    std::vector<Aabb> prims(100000);
    for (size_t i = 0; i < prims.size(); ++i) {
        float s = 1.0f + float(i);
        prims[i].grow(glm::vec3(-s));
        prims[i].grow(glm::vec3(s));
    }
    BvhBuildOptions o;
    o.max_leaf_size = 1;
    Bvh bvh = build_bvh(prims, o);
    check_invariants(bvh, prims, o);
    EXPECT_LE(bvh.max_depth(), 20u);
}

// The multi-threaded build gives the one-thread build's Bvh node for node (bounds to the bit, links,
// ranges, depths) and the same primitive order, whatever the thread count, on sets large enough to be
// split across threads: random triangles, clusters of identical centroids (median splits decided by
// nth_element on the range's order), a flat set, skipped primitives, and the depth fallback.
TEST(BvhBuilder, ThreadsGiveTheSameTree) {
    std::mt19937 rng(9);
    std::vector<std::vector<Aabb>> sets;
    sets.push_back(triangle_bounds(test::random_soup(rng, 200000, 10.0f, 0.05f)));
    std::vector<Aabb> clusters = triangle_bounds(test::random_soup(rng, 60000, 3.0f, 0.1f));
    for (size_t i = 0; i < clusters.size(); i += 3) { // every third box centred on one of 5 points
        const float c = float(i % 5);
        clusters[i] = Aabb{};
        clusters[i].grow(glm::vec3(c - 0.01f * float(i % 7 + 1)));
        clusters[i].grow(glm::vec3(c + 0.01f * float(i % 7 + 1)));
    }
    for (size_t i = 1; i < clusters.size(); i += 97) clusters[i] = Aabb{}; // skipped
    clusters[2].lo.x = std::nanf("");                                      // skipped
    sets.push_back(clusters);
    std::vector<Aabb> flat = triangle_bounds(test::random_soup(rng, 80000, 5.0f, 0.02f));
    for (Aabb& b : flat) b.lo.z = b.hi.z = 1.0f;
    sets.push_back(flat);
    std::vector<Aabb> nested(70000); // identical centroids: median splits all the way down
    for (size_t i = 0; i < nested.size(); ++i) {
        nested[i].grow(glm::vec3(-1.0f - float(i)));
        nested[i].grow(glm::vec3(1.0f + float(i)));
    }
    sets.push_back(nested);
    for (size_t s = 0; s < sets.size(); ++s) {
        for (uint32_t leaf : {1u, 4u}) {
            SCOPED_TRACE("set " + std::to_string(s) + " leaf " + std::to_string(leaf));
            BvhBuildOptions o;
            o.max_leaf_size = leaf;
            o.threads = 1;
            const Bvh one = build_bvh(sets[s], o);
            check_invariants(one, sets[s], o);
            for (uint32_t threads : {2u, 3u, 8u, 0u}) {
                o.threads = threads;
                const Bvh many = build_bvh(sets[s], o);
                ASSERT_EQ(many.prim_indices, one.prim_indices) << threads << " threads";
                ASSERT_EQ(many.nodes.size(), one.nodes.size()) << threads << " threads";
                for (size_t i = 0; i < one.nodes.size(); ++i) {
                    const BvhNode &a = one.nodes[i], &b = many.nodes[i];
                    ASSERT_TRUE(std::memcmp(&a.bounds, &b.bounds, sizeof(Aabb)) == 0 && a.left == b.left &&
                                a.right == b.right && a.first == b.first && a.count == b.count &&
                                a.parent == b.parent && a.depth == b.depth)
                        << threads << " threads, node " << i;
                }
            }
        }
    }
}

// A CPU closest-hit traversal over the GpuBvhNode array (what the shaders do) must match the Bvh.
bool gpu_closest(const std::vector<GpuBvhNode>& g, const MeshBvh& m, const Ray& ray, float tmax, Hit& hit) {
    if (g.empty()) return false;
    const glm::vec3 inv = nb_safe_inv_dir(ray.dir);
    uint32_t stack[NB_BVH_MAX_DEPTH];
    uint32_t size = 0;
    bool found = false;
    auto leaf = [&](uint32_t ref) {
        for (uint32_t k = nb_leaf_first(ref); k < nb_leaf_first(ref) + nb_leaf_count(ref); ++k) {
            float t, u, v;
            if (nb_intersect_triangle(ray.org, ray.dir, m.vertices[3 * k], m.vertices[3 * k + 1], m.vertices[3 * k + 2],
                                      0.0f, tmax, t, u, v)) {
                tmax = t;
                hit = Hit{t, m.bvh.prim_indices[k], u, v};
                found = true;
            }
        }
    };
    stack[size++] = 0;
    while (size > 0) {
        const GpuBvhNode& n = g[stack[--size]];
        float tl, tr;
        bool hl = nb_intersect_aabb(ray.org, inv, n.lmin, n.lmax, 0.0f, tmax, tl);
        bool hr = n.right != NB_CHILD_NONE && nb_intersect_aabb(ray.org, inv, n.rmin, n.rmax, 0.0f, tmax, tr);
        uint32_t refs[2] = {n.left, n.right};
        bool hits[2] = {hl, hr};
        for (int c = 0; c < 2; ++c) {
            if (!hits[c]) continue;
            if (nb_is_leaf(refs[c])) leaf(refs[c]);
            else {
                EXPECT_LT(size, NB_BVH_MAX_DEPTH);
                stack[size++] = refs[c];
            }
        }
    }
    return found;
}

TEST(BvhGpuLayout, RoundTripTraversalMatches) {
    std::mt19937 rng(9);
    for (uint32_t n : {1u, 2u, 5u, 3000u}) {
        Mesh mesh = test::make_mesh(test::random_soup(rng, n, 1.0f, 0.3f));
        for (uint32_t leaf : {1u, 4u, 16u}) {
            BvhBuildOptions o;
            o.max_leaf_size = leaf;
            MeshBvh m = build_mesh_bvh(mesh, o);
            auto g = to_gpu_layout(m.bvh);
            // Leaf refs cover prim_indices exactly once; interior refs are in range.
            std::vector<int> cover(m.triangle_count(), 0);
            for (const GpuBvhNode& node : g)
                for (uint32_t ref : {node.left, node.right}) {
                    if (ref == NB_CHILD_NONE) continue;
                    if (nb_is_leaf(ref)) {
                        for (uint32_t k = 0; k < nb_leaf_count(ref); ++k) ++cover.at(nb_leaf_first(ref) + k);
                    } else {
                        EXPECT_LT(ref, g.size());
                        EXPECT_GT(ref, 0u);
                    }
                }
            for (int c : cover) ASSERT_EQ(c, 1);
            for (int r = 0; r < 300; ++r) {
                Ray ray = test::random_ray(rng, glm::vec3(0.0f), 1.0f);
                Hit a, b;
                bool ha = intersect_closest(m, ray, 0.0f, NB_INF, a);
                bool hb = gpu_closest(g, m, ray, NB_INF, b);
                ASSERT_EQ(ha, hb);
                if (ha) {
                    EXPECT_EQ(a.t, b.t);
                }
            }
        }
    }
}

} // namespace
} // namespace nbvh
