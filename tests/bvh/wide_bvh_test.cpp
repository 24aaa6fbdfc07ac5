// The 4-wide quantized BLAS layout (engine/bvh/wide_bvh.h, shaders/shared/wide_bvh_node.h): structure,
// conservative quantization, and the CPU run of the shaders' loop (NB_TRAVERSE_WIDE) against the
// brute-force reference on random soups, degenerate and flat sets, one triangle, > 2^16 triangles and
// thin boxes far from the origin, with random, edge/vertex-aimed and grazing rays.
#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <random>

#include "engine/bvh/aabb_ops.h"
#include "engine/bvh/wide_bvh.h"
#include "tests/bvh/test_geometry.h"

namespace nbvh {
namespace {

uint32_t child_ref(const GpuWideNode& n, uint32_t i) { return nb_wide_child(n, i); }

// Structure: leaf refs cover the leaf order exactly once, interior refs point forward (depth-first)
// and are each referenced once, every node but an empty root has a child, decoded boxes contain the exact
// ones and stay within two quantization steps of them, and no path needs more than the shader's stack.
void check_layout(const std::vector<GpuWideNode>& g, const std::vector<WideChildBounds>& exact, const MeshBvh& m) {
    ASSERT_FALSE(g.empty());
    ASSERT_EQ(exact.size(), g.size());
    std::vector<int> cover(m.triangle_count(), 0), parents(g.size(), 0);
    for (size_t w = 0; w < g.size(); ++w) {
        uint32_t children = 0;
        for (uint32_t i = 0; i < NB_WIDE_ARITY; ++i) {
            const uint32_t ref = child_ref(g[w], i);
            if (ref == NB_CHILD_NONE) continue;
            ++children;
            if (nb_is_leaf(ref)) {
                for (uint32_t k = 0; k < nb_leaf_count(ref); ++k) ++cover.at(nb_leaf_first(ref) + k);
            } else {
                ASSERT_GT(ref, w);
                ASSERT_LT(ref, g.size());
                ++parents[ref];
            }
            glm::vec3 lo, hi;
            nb_wide_child_bounds(g[w], i, lo, hi);
            const Aabb& e = exact[w][i];
            ASSERT_TRUE(contains(Aabb{lo, hi}, e)) << "node " << w << " child " << i;
            for (int a = 0; a < 3; ++a) {
                const float step = g[w].scale[a];
                // A power of two (exact products), and the decoded planes are tight up to rounding.
                int exp;
                EXPECT_EQ(std::frexp(step, &exp), 0.5f);
                const float slack = 2.0f * step + 4.0f * FLT_EPSILON * std::abs(g[w].origin[a]);
                EXPECT_GE(lo[a], e.lo[a] - slack);
                EXPECT_LE(hi[a], e.hi[a] + slack);
            }
        }
        EXPECT_TRUE(children > 0 || (g.size() == 1 && m.triangle_count() == 0));
    }
    for (int c : cover) ASSERT_EQ(c, 1);
    for (size_t w = 1; w < g.size(); ++w) ASSERT_EQ(parents[w], 1) << "node " << w;
    // Worst stack of any root-to-leaf path: each node pushes its other children.
    std::vector<uint32_t> need(g.size(), 0);
    uint32_t worst = 0;
    for (size_t w = 0; w < g.size(); ++w) {
        uint32_t children = 0;
        for (uint32_t i = 0; i < NB_WIDE_ARITY; ++i) children += child_ref(g[w], i) != NB_CHILD_NONE;
        const uint32_t below = need[w] + (children > 0 ? children - 1 : 0);
        worst = std::max(worst, below);
        for (uint32_t i = 0; i < NB_WIDE_ARITY; ++i) {
            const uint32_t ref = child_ref(g[w], i);
            if (ref != NB_CHILD_NONE && !nb_is_leaf(ref)) need[ref] = below;
        }
    }
    EXPECT_LE(worst, NB_WIDE_STACK_SIZE);
}

// Wide traversal vs brute force: same hit/miss, same t, same triangle (or a tie in t); any hit agrees.
void expect_same(const Mesh& mesh, const MeshBvh& m, const std::vector<GpuWideNode>& g, const Ray& ray,
                 const std::vector<Material>* materials = nullptr) {
    Hit ref, wide, any;
    const bool h_ref = intersect_closest_brute_force(mesh, ray, 0.0f, NB_INF, ref, materials);
    const bool h_wide = wide_intersect(g, m, ray, 0.0f, NB_INF, false, wide);
    const bool h_any = wide_intersect(g, m, ray, 0.0f, NB_INF, true, any);
    ASSERT_EQ(h_ref, h_wide) << "org " << ray.org.x << "," << ray.org.y << "," << ray.org.z;
    ASSERT_EQ(h_ref, h_any);
    if (!h_ref) return;
    ASSERT_EQ(ref.t, wide.t);
    if (ref.triangle != wide.triangle) {
        // Only a tie: the other triangle hits at the same t.
        Hit other;
        ASSERT_TRUE(intersect_closest_brute_force(mesh, ray, wide.t, wide.t, other, materials));
    }
    EXPECT_GE(any.t, ref.t);
}

// Rays: random through the soup's box, aimed at vertices and edge midpoints (shared edges), nearly in a
// triangle's plane (grazing), and axis-parallel from a random face point of the bounds.
void check_rays(const Mesh& mesh, const MeshBvh& m, const std::vector<GpuWideNode>& g, std::mt19937& rng, int count,
                const std::vector<Material>* materials = nullptr) {
    const Aabb b = m.bounds();
    const glm::vec3 c = b.center();
    const float r = std::max(0.5f * glm::length(b.extent()), 1e-3f);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::uniform_int_distribution<uint32_t> tri(0, mesh.triangle_count() - 1);
    for (int i = 0; i < count; ++i) {
        Ray ray = test::random_ray(rng, c, r);
        const uint32_t t = tri(rng);
        const glm::vec3 v0 = mesh.positions[mesh.indices[3 * t]], v1 = mesh.positions[mesh.indices[3 * t + 1]],
                        v2 = mesh.positions[mesh.indices[3 * t + 2]];
        switch (i % 5) {
        case 1: ray.dir = v0 - ray.org; break;                // a vertex
        case 2: ray.dir = 0.5f * (v1 + v2) - ray.org; break;  // an edge midpoint
        case 3: {                                             // grazing: from the plane, barely tilted
            const glm::vec3 p = v0 + u(rng) * (v1 - v0) + u(rng) * (v2 - v0);
            const glm::vec3 n = glm::cross(v1 - v0, v2 - v0);
            const glm::vec3 along = v1 - v0;
            ray.org = p - 3.0f * along + (glm::length(n) > 0.0f ? 1e-4f * r * glm::normalize(n) * (u(rng) - 0.5f) : glm::vec3(0.0f));
            ray.dir = along;
            break;
        }
        case 4: { // axis-parallel, starting on a face of the bounds
            const int a = int(rng() % 3);
            ray.org = b.lo + glm::vec3(u(rng), u(rng), u(rng)) * b.extent();
            ray.org[a] = b.lo[a];
            ray.dir = glm::vec3(0.0f);
            ray.dir[a] = 1.0f;
            break;
        }
        default: break;
        }
        expect_same(mesh, m, g, ray, materials);
        if (::testing::Test::HasFatalFailure()) return;
    }
}

void check_mesh(const Mesh& mesh, uint32_t leaf_size, std::mt19937& rng, int rays) {
    BvhBuildOptions o = default_blas_options();
    o.max_leaf_size = leaf_size;
    const MeshBvh m = build_mesh_bvh(mesh, o);
    std::vector<WideChildBounds> exact;
    const std::vector<GpuWideNode> g = to_wide_layout(m.bvh, &exact);
    check_layout(g, exact, m);
    if (::testing::Test::HasFatalFailure()) return;
    check_rays(mesh, m, g, rng, rays);
}

TEST(WideBvh, RandomSoupsMatchBruteForce) {
    std::mt19937 rng(21);
    for (uint32_t n : {1u, 2u, 3u, 5u, 17u, 3000u})
        for (uint32_t leaf : {1u, 4u, 16u}) {
            SCOPED_TRACE("n " + std::to_string(n) + " leaf " + std::to_string(leaf));
            check_mesh(test::make_mesh(test::random_soup(rng, n, 1.0f, 0.3f)), leaf, rng, 300);
            if (::testing::Test::HasFatalFailure()) return;
        }
}

// Flat (z = 0) and axis-aligned triangles, zero-area ones, and 40 copies of one triangle (identical
// centroids: leaves of 16 under a median split).
TEST(WideBvh, DegenerateAndFlatSetsMatchBruteForce) {
    std::mt19937 rng(22);
    std::vector<glm::vec3> flat = test::random_soup(rng, 500, 1.0f, 0.2f);
    for (glm::vec3& p : flat) p.z = 0.0f;
    std::vector<glm::vec3> mixed = flat;
    for (int i = 0; i < 40; ++i) mixed.insert(mixed.end(), {glm::vec3(0.1f), glm::vec3(0.3f, 0.1f, 0.1f), glm::vec3(0.1f, 0.3f, 0.1f)});
    for (int i = 0; i < 30; ++i) { // zero-area (repeated vertex) and collinear
        const glm::vec3 p(0.01f * float(i), 0.5f, 0.25f);
        mixed.insert(mixed.end(), {p, p, p + glm::vec3(0.1f, 0.0f, 0.0f)});
        mixed.insert(mixed.end(), {p, p + glm::vec3(0.1f, 0.0f, 0.0f), p + glm::vec3(0.2f, 0.0f, 0.0f)});
    }
    for (uint32_t leaf : {1u, 4u, 16u}) {
        check_mesh(test::make_mesh(flat), leaf, rng, 400);
        check_mesh(test::make_mesh(mixed), leaf, rng, 400);
        if (::testing::Test::HasFatalFailure()) return;
    }
    // Rays in the plane of the flat set (never hit, must not report NaN hits) and along z onto it.
    const Mesh mesh = test::make_mesh(flat);
    const MeshBvh m = build_mesh_bvh(mesh);
    const std::vector<GpuWideNode> g = to_wide_layout(m.bvh);
    std::uniform_real_distribution<float> u(-1.2f, 1.2f);
    for (int i = 0; i < 300; ++i) {
        expect_same(mesh, m, g, Ray{glm::vec3(u(rng), u(rng), 0.0f), glm::vec3(u(rng), u(rng), 0.0f)});
        expect_same(mesh, m, g, Ray{glm::vec3(u(rng), u(rng), 1.0f), glm::vec3(0.0f, 0.0f, -1.0f)});
        expect_same(mesh, m, g, Ray{glm::vec3(u(rng), u(rng), 0.0f), glm::vec3(0.0f, 0.0f, 1.0f)});
        if (::testing::Test::HasFatalFailure()) return;
    }
}

TEST(WideBvh, SingleTriangleAndEmptyMesh) {
    std::mt19937 rng(23);
    const Mesh one = test::make_mesh({glm::vec3(0, 0, 0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)});
    const MeshBvh m = build_mesh_bvh(one);
    const std::vector<GpuWideNode> g = to_wide_layout(m.bvh);
    ASSERT_EQ(g.size(), 1u);
    EXPECT_EQ(g[0].child0, nb_make_leaf(0, 1));
    EXPECT_EQ(g[0].child1, NB_CHILD_NONE);
    EXPECT_EQ(g[0].child3, NB_CHILD_NONE);
    check_mesh(one, 4, rng, 500);
    Hit hit;
    ASSERT_TRUE(wide_intersect(g, m, Ray{glm::vec3(0.25f, 0.25f, 1.0f), glm::vec3(0, 0, -1)}, 0.0f, NB_INF, false, hit));
    EXPECT_EQ(hit.t, 1.0f);
    // An empty BVH: one node without children, nothing is hit.
    const std::vector<GpuWideNode> e = to_wide_layout(Bvh{});
    ASSERT_EQ(e.size(), 1u);
    EXPECT_EQ(e[0].child0, NB_CHILD_NONE);
    EXPECT_FALSE(wide_intersect(e, MeshBvh{}, Ray{}, 0.0f, NB_INF, false, hit));
}

// More triangles than 16-bit indices hold; the wide tree has well under half the binary interior nodes.
TEST(WideBvh, ManyTrianglesMatchBruteForce) {
    std::mt19937 rng(24);
    const Mesh mesh = test::make_mesh(test::random_soup(rng, 70000, 1.0f, 0.02f));
    const MeshBvh m = build_mesh_bvh(mesh);
    std::vector<WideChildBounds> exact;
    const std::vector<GpuWideNode> g = to_wide_layout(m.bvh, &exact);
    check_layout(g, exact, m);
    const size_t interior = std::count_if(m.bvh.nodes.begin(), m.bvh.nodes.end(), [](const BvhNode& n) { return !n.is_leaf(); });
    EXPECT_LT(double(g.size()), 0.5 * double(interior)) << g.size() << " wide nodes, " << interior << " binary";
    check_rays(mesh, m, g, rng, 150);
}

// Thin boxes 1e5 from the origin: the node frame's steps are far below the float spacing there, so only
// the outward rounding of the decoded planes keeps the boxes conservative.
TEST(WideBvh, ThinBoxesFarFromTheOriginMatchBruteForce) {
    std::mt19937 rng(25);
    for (const glm::vec3 offset : {glm::vec3(1e5f, -1e5f, 1e5f), glm::vec3(-3e5f, 2e5f, 0.0f)}) {
        std::vector<glm::vec3> v = test::random_soup(rng, 2000, 1.0f, 1e-3f, offset);
        for (size_t i = 0; i < v.size(); i += 6) v[i].y = v[i + 1].y = v[i + 2].y = offset.y; // flat in y
        for (uint32_t leaf : {1u, 4u}) {
            check_mesh(test::make_mesh(v), leaf, rng, 400);
            if (::testing::Test::HasFatalFailure()) return;
        }
    }
}

// Single-sided triangles are culled from behind exactly as the brute-force reference does.
TEST(WideBvh, SingleSidedTrianglesMatchBruteForce) {
    std::mt19937 rng(26);
    Mesh mesh = test::make_mesh(test::random_soup(rng, 2000, 1.0f, 0.2f));
    std::vector<Material> materials(2);
    materials[0].double_sided = true;
    materials[1].double_sided = false;
    for (uint32_t& mat : mesh.triangle_material) mat = rng() % 2;
    MeshBvh m = build_mesh_bvh(mesh);
    m.single_sided = single_sided_flags(mesh, m, materials);
    ASSERT_FALSE(m.single_sided.empty());
    const std::vector<GpuWideNode> g = to_wide_layout(m.bvh);
    check_rays(mesh, m, g, rng, 600, &materials);
}

TEST(WideBvh, BoundsTooWideToQuantizeAreAnError) {
    Bvh bvh;
    BvhNode leaf;
    leaf.count = 1;
    leaf.bounds.grow(glm::vec3(-3e38f));
    leaf.bounds.grow(glm::vec3(3e38f));
    bvh.nodes.push_back(leaf);
    bvh.prim_indices.push_back(0);
    EXPECT_THROW(to_wide_layout(bvh), Error);
}

} // namespace
} // namespace nbvh
