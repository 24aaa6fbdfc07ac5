// Mesh BLAS closest/any hit against brute force on random and degenerate triangle soups.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "engine/bvh/mesh_bvh.h"
#include "test_geometry.h"

namespace nbvh {
namespace {

// Ties (duplicate or coplanar triangles at the same t) may pick a different triangle; the BVH's
// choice must then hit at exactly the same t.
void expect_same(const Mesh& mesh, const MeshBvh& m, const Ray& ray, float tmin, float tmax) {
    Hit a, b;
    bool ha = intersect_closest(m, ray, tmin, tmax, a);
    bool hb = intersect_closest_brute_force(mesh, ray, tmin, tmax, b);
    ASSERT_EQ(ha, hb);
    ASSERT_EQ(intersect_any(m, ray, tmin, tmax), hb);
    if (!ha) return;
    ASSERT_EQ(a.t, b.t) << "bvh triangle " << a.triangle << " brute force triangle " << b.triangle << " dt "
                        << (a.t - b.t);
    ASSERT_TRUE(std::isfinite(a.u) && std::isfinite(a.v));
    if (a.triangle != b.triangle) {
        const uint32_t* i = &mesh.indices[3 * size_t(a.triangle)];
        float t, u, v;
        ASSERT_TRUE(nb_intersect_triangle(ray.org, ray.dir, mesh.positions[i[0]], mesh.positions[i[1]],
                                          mesh.positions[i[2]], tmin, tmax, t, u, v));
        ASSERT_EQ(t, a.t);
    } else {
        ASSERT_EQ(a.u, b.u);
        ASSERT_EQ(a.v, b.v);
    }
}

void compare(const Mesh& mesh, std::mt19937& rng, glm::vec3 center, float radius, int rays, int min_hits = 1) {
    MeshBvh m = build_mesh_bvh(mesh);
    int hits = 0;
    for (int r = 0; r < rays; ++r) {
        Ray ray = test::random_ray(rng, center, radius);
        expect_same(mesh, m, ray, 0.0f, NB_INF);
        if (::testing::Test::HasFatalFailure()) return;
        Hit h;
        hits += intersect_closest(m, ray, 0.0f, NB_INF, h);
        // A limited interval starting inside the scene.
        expect_same(mesh, m, ray, 0.3f, 0.8f);
    }
    EXPECT_GE(hits, min_hits);
}

TEST(MeshBvh, RandomSoups) {
    std::mt19937 rng(1);
    compare(test::make_mesh(test::random_soup(rng, 3000, 1.0f, 0.1f)), rng, glm::vec3(0.0f), 1.0f, 800, 100);
    compare(test::make_mesh(test::random_soup(rng, 500, 1.0f, 1.0f)), rng, glm::vec3(0.0f), 1.0f, 800, 100);
    // 1e-3 and 1e5 scales, and 1e5 from the origin.
    compare(test::make_mesh(test::random_soup(rng, 2000, 1e-3f, 1e-4f)), rng, glm::vec3(0.0f), 1e-3f, 500, 50);
    compare(test::make_mesh(test::random_soup(rng, 2000, 1e5f, 1e4f)), rng, glm::vec3(0.0f), 1e5f, 500, 50);
    compare(test::make_mesh(test::random_soup(rng, 2000, 10.0f, 1.0f, glm::vec3(1e5f, -1e5f, 1e5f))), rng,
            glm::vec3(1e5f, -1e5f, 1e5f), 10.0f, 500, 50);
}

TEST(MeshBvh, DegenerateSoups) {
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    auto base = test::random_soup(rng, 1000, 1.0f, 0.2f);

    // Zero-area (collinear and repeated vertices) mixed with regular triangles.
    auto zero = base;
    for (size_t t = 0; t < zero.size() / 3; t += 2) {
        zero[3 * t + 2] = (t % 4 == 0) ? zero[3 * t] : zero[3 * t] + 2.0f * (zero[3 * t + 1] - zero[3 * t]);
    }
    compare(test::make_mesh(zero), rng, glm::vec3(0.0f), 1.0f, 500, 50);

    // Every triangle twice (duplicates), and once more reversed.
    auto dup = base;
    for (size_t t = 0; t < base.size() / 3; ++t) {
        dup.insert(dup.end(), {base[3 * t], base[3 * t + 1], base[3 * t + 2]});
        dup.insert(dup.end(), {base[3 * t + 2], base[3 * t + 1], base[3 * t]});
    }
    compare(test::make_mesh(dup), rng, glm::vec3(0.0f), 1.0f, 500, 50);

    // Coplanar: all in z = 0, rays from random directions (also grazing ones with dir.z = 0).
    auto flat = base;
    for (glm::vec3& p : flat) p.z = 0.0f;
    Mesh flat_mesh = test::make_mesh(flat);
    compare(flat_mesh, rng, glm::vec3(0.0f), 1.0f, 500, 50);
    MeshBvh fm = build_mesh_bvh(flat_mesh);
    for (int r = 0; r < 300; ++r) {
        Ray ray{glm::vec3(u(rng) * 3.0f, u(rng) * 3.0f, 0.0f), glm::vec3(u(rng), u(rng), 0.0f)};
        Hit h;
        EXPECT_FALSE(intersect_closest(fm, ray, 0.0f, NB_INF, h)); // in-plane rays never hit
        Ray axis{glm::vec3(-3.0f, u(rng), 0.0f), glm::vec3(1.0f, 0.0f, 0.0f)};
        EXPECT_FALSE(intersect_closest(fm, axis, 0.0f, NB_INF, h));
        // Axis-parallel rays perpendicular to the plane: exact brute-force agreement.
        Ray down{glm::vec3(u(rng), u(rng), 2.0f), glm::vec3(0.0f, 0.0f, -1.0f)};
        expect_same(flat_mesh, fm, down, 0.0f, NB_INF);
    }

    // Flat along an axis: all x = 0.5 (a thin wall), axis-parallel rays along x.
    auto wall = base;
    for (glm::vec3& p : wall) p.x = 0.5f;
    Mesh wall_mesh = test::make_mesh(wall);
    MeshBvh wm = build_mesh_bvh(wall_mesh);
    int hits = 0;
    for (int r = 0; r < 500; ++r) {
        Ray ray{glm::vec3(-2.0f, u(rng), u(rng)), glm::vec3(1.0f, 0.0f, 0.0f)};
        expect_same(wall_mesh, wm, ray, 0.0f, NB_INF);
        Hit h;
        if (intersect_closest(wm, ray, 0.0f, NB_INF, h)) {
            ++hits;
            EXPECT_NEAR(h.t, 2.5f, 1e-6f);
        }
    }
    EXPECT_GT(hits, 50);

    // Everything in one point: no hit at all, no crash.
    std::vector<glm::vec3> point(300, glm::vec3(0.25f, 0.5f, -0.75f));
    Mesh point_mesh = test::make_mesh(point);
    MeshBvh pm = build_mesh_bvh(point_mesh);
    for (int r = 0; r < 200; ++r) {
        Ray ray = test::random_ray(rng, glm::vec3(0.25f, 0.5f, -0.75f), 0.0f);
        Hit h;
        EXPECT_FALSE(intersect_closest(pm, ray, 0.0f, NB_INF, h));
        EXPECT_FALSE(intersect_any(pm, ray, 0.0f, NB_INF));
    }
}

TEST(MeshBvh, InvalidTrianglesAreSkipped) {
    std::mt19937 rng(3);
    Mesh mesh = test::make_mesh(test::random_soup(rng, 200, 1.0f, 0.3f));
    mesh.positions[4].y = std::nanf("");           // triangle 1
    mesh.positions[7].x = INFINITY;                // triangle 2
    mesh.indices[9] = 100000;                      // triangle 3: out of range
    MeshBvh m = build_mesh_bvh(mesh);
    EXPECT_EQ(m.triangle_count(), 197u);
    for (uint32_t id : m.bvh.prim_indices) EXPECT_TRUE(id != 1 && id != 2 && id != 3);
    for (int r = 0; r < 300; ++r) expect_same(mesh, m, test::random_ray(rng, glm::vec3(0.0f), 1.0f), 0.0f, NB_INF);

    Mesh empty;
    MeshBvh e = build_mesh_bvh(empty);
    Hit h;
    EXPECT_FALSE(intersect_closest(e, Ray{}, 0.0f, NB_INF, h));
    EXPECT_FALSE(intersect_any(e, Ray{}, 0.0f, NB_INF));
}

// traverse_cut: interior nodes treated as leaves (an N-BVH cut). Stopping at the first callback
// visits exactly one cut node; shrinking tmax to each visited entry finds the nearest-entered one.
TEST(MeshBvh, TraverseCutVisitsCutNodes) {
    std::mt19937 rng(4);
    MeshBvh m = build_mesh_bvh(test::make_mesh(test::random_soup(rng, 2000, 1.0f, 0.05f)));
    auto in_cut = [&](uint32_t n) { return m.bvh.nodes[n].depth == 3; };
    int with_hits = 0;
    for (int r = 0; r < 200; ++r) {
        Ray ray = test::random_ray(rng, glm::vec3(0.0f), 1.0f);
        uint32_t visited = 0;
        traverse_cut(m.bvh, ray, 0.0f, NB_INF, in_cut, [&](uint32_t n, float, float&) {
            EXPECT_TRUE(m.bvh.nodes[n].depth == 3 || (m.bvh.nodes[n].is_leaf() && m.bvh.nodes[n].depth < 3));
            ++visited;
            return true;
        });
        EXPECT_LE(visited, 1u);

        float nearest = NB_INF;
        traverse_cut(m.bvh, ray, 0.0f, NB_INF, in_cut, [&](uint32_t, float t_near, float& tmax) {
            nearest = std::min(nearest, t_near);
            tmax = t_near;
            return false;
        });
        float best = NB_INF;
        for (const BvhNode& n : m.bvh.nodes) {
            if (n.depth != 3 && !(n.is_leaf() && n.depth < 3)) continue;
            float tn;
            if (nb_intersect_aabb(ray.org, nb_safe_inv_dir(ray.dir), n.bounds.lo, n.bounds.hi, 0.0f, NB_INF, tn))
                best = std::min(best, tn);
        }
        EXPECT_EQ(nearest, best);
        EXPECT_EQ(visited == 1, best < NB_INF);
        with_hits += best < NB_INF;
    }
    EXPECT_GT(with_hits, 20);
}

} // namespace
} // namespace nbvh
