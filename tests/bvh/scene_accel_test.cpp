// Two-level scene acceleration (TLAS over instances) against brute force, with rotated, mirrored,
// non-uniformly scaled and invalid instances.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/bvh/scene_accel.h"
#include "engine/core/error.h"
#include "test_geometry.h"

namespace nbvh {
namespace {

Scene make_scene(std::mt19937& rng) {
    Scene s;
    s.meshes.push_back(test::make_mesh(test::random_soup(rng, 400, 1.0f, 0.2f)));
    s.meshes.push_back(test::make_mesh(test::random_soup(rng, 50, 0.5f, 0.5f, glm::vec3(0.3f, 0.0f, 0.0f))));
    s.meshes.push_back(Mesh{}); // no triangles: its instances are skipped
    auto add = [&](uint32_t mesh, glm::mat4 m) {
        Instance i;
        i.mesh = mesh;
        i.object_to_world = m;
        s.instances.push_back(i);
    };
    const glm::mat4 I(1.0f);
    add(0, I);
    add(0, glm::translate(I, glm::vec3(3.0f, 0.0f, 0.0f)) * glm::rotate(I, 0.7f, glm::normalize(glm::vec3(1, 2, 3))));
    add(0, glm::translate(I, glm::vec3(-3.0f, 0.5f, 0.0f)) * glm::scale(I, glm::vec3(-1.0f, 1.0f, 1.0f))); // mirrored
    add(1, glm::translate(I, glm::vec3(0.0f, 3.0f, 1.0f)) * glm::rotate(I, 2.0f, glm::vec3(0, 1, 0)) *
               glm::scale(I, glm::vec3(2.0f, 0.5f, -1.0f))); // non-uniform, mirrored
    add(1, glm::translate(I, glm::vec3(0.2f, 0.1f, 0.0f)) * glm::scale(I, glm::vec3(-1.0f))); // overlaps instance 0
    add(0, glm::scale(I, glm::vec3(1.0f, 0.0f, 1.0f)));  // singular: skipped
    add(7, I);                                              // mesh out of range: skipped
    add(2, I);                                              // empty mesh: skipped
    glm::mat4 nan_m = I;
    nan_m[3][0] = std::nanf("");
    add(0, nan_m);                                          // non-finite: skipped
    return s;
}

TEST(SceneAccel, StructureAndSkippedInstances) {
    std::mt19937 rng(1);
    Scene s = make_scene(rng);
    SceneAccel a = build_scene_accel(s);
    ASSERT_EQ(a.meshes.size(), 3u);
    EXPECT_EQ(a.tlas.prim_indices.size(), 5u); // the 5 valid instances
    for (uint32_t id : a.tlas.prim_indices) EXPECT_LT(id, 5u);
    for (size_t i = 5; i < s.instances.size(); ++i) EXPECT_TRUE(a.instance_bounds[i].empty());
    EXPECT_FALSE(to_gpu_layout(a.tlas).empty());
}

TEST(SceneAccel, ClosestAndAnyHitMatchBruteForce) {
    std::mt19937 rng(2);
    Scene s = make_scene(rng);
    SceneAccel a = build_scene_accel(s);
    int hits = 0, per_instance[5] = {};
    for (int r = 0; r < 3000; ++r) {
        Ray ray = test::random_ray(rng, glm::vec3(0.0f, 1.0f, 0.0f), 4.0f);
        SceneHit h1, h2;
        bool b1 = intersect_closest(a, ray, 0.0f, NB_INF, h1);
        bool b2 = intersect_closest_brute_force(s, ray, 0.0f, NB_INF, h2);
        ASSERT_EQ(b1, b2);
        ASSERT_EQ(intersect_any(a, ray, 0.0f, NB_INF), b2);
        if (!b1) continue;
        ++hits;
        ASSERT_EQ(h1.t, h2.t);
        ASSERT_LT(h1.instance, 5u);
        ++per_instance[h1.instance];
        // The hit lies on the world-space triangle (t is a world-ray parameter).
        const Mesh& mesh = s.meshes[s.instances[h1.instance].mesh];
        const glm::mat4& m = s.instances[h1.instance].object_to_world;
        glm::vec3 v[3];
        for (int k = 0; k < 3; ++k)
            v[k] = glm::vec3(m * glm::vec4(mesh.positions[mesh.indices[3 * h1.triangle + k]], 1.0f));
        glm::vec3 p_bary = (1.0f - h1.u - h1.v) * v[0] + h1.u * v[1] + h1.v * v[2];
        glm::vec3 p_ray = ray.org + h1.t * ray.dir;
        EXPECT_LT(glm::length(p_bary - p_ray), 1e-4f);
        // Limited interval: also identical.
        bool c1 = intersect_closest(a, ray, h1.t * 1.001f, NB_INF, h1);
        bool c2 = intersect_closest_brute_force(s, ray, h2.t * 1.001f, NB_INF, h2);
        ASSERT_EQ(c1, c2);
        if (c1) {
            ASSERT_EQ(h1.t, h2.t);
        }
    }
    EXPECT_GT(hits, 300);
    for (int i = 0; i < 5; ++i) EXPECT_GT(per_instance[i], 0) << "instance " << i << " never hit";
}

bool same_box(const Aabb& a, const Aabb& b) {
    return std::memcmp(&a, &b, sizeof(Aabb)) == 0; // bit for bit
}

// bounds_only_mesh_bvh gives the root box the builder gives, to the bit, on the meshes the builder treats
// specially: skipped triangles (an index out of range, NaN and infinite vertices), a flat mesh, one far from
// the origin at float's range, one whose every triangle is skipped.
TEST(SceneAccel, BoundsOnlyIsTheBuiltRootBox) {
    std::mt19937 rng(5);
    std::vector<Mesh> meshes;
    meshes.push_back(test::make_mesh(test::random_soup(rng, 300, 1.0f, 0.1f)));
    Mesh bad = test::make_mesh(test::random_soup(rng, 20, 2.0f, 0.3f, glm::vec3(5.0f, 0.0f, 0.0f)));
    bad.positions[4].y = std::nanf("");                          // triangle 1 skipped
    bad.positions[9].z = std::numeric_limits<float>::infinity(); // triangle 3 skipped
    bad.positions[30] = glm::vec3(1.0e6f);                       // triangle 10 out on its own: kept
    bad.indices[3 * 5 + 1] = 1000u;                              // triangle 5: index out of range
    meshes.push_back(bad);
    std::vector<glm::vec3> flat = test::random_soup(rng, 40, 1.0f, 0.2f);
    for (glm::vec3& p : flat) p.z = 0.25f;
    meshes.push_back(test::make_mesh(flat));
    meshes.push_back(
        test::make_mesh(test::random_soup(rng, 30, 1.0e37f, 1.0e36f, glm::vec3(-2.0e38f, 0.0f, 3.0e38f))));
    Mesh none = test::make_mesh(test::random_soup(rng, 2, 1.0f, 0.1f));
    none.positions[0].x = std::nanf("");
    none.indices[3] = 99u;
    meshes.push_back(none);
    meshes.push_back(Mesh{});
    for (size_t m = 0; m < meshes.size(); ++m) {
        const MeshBvh built = build_mesh_bvh(meshes[m]), only = bounds_only_mesh_bvh(meshes[m]);
        EXPECT_TRUE(only.bounds_only);
        EXPECT_FALSE(built.bounds_only);
        EXPECT_EQ(only.empty(), built.empty()) << "mesh " << m;
        EXPECT_TRUE(same_box(only.bounds(), built.bounds())) << "mesh " << m;
        EXPECT_TRUE(only.vertices.empty());
    }
    EXPECT_TRUE(bounds_only_mesh_bvh(meshes[4]).empty()) << "every triangle skipped";
    EXPECT_EQ(bounds_only_mesh_bvh(meshes[1]).bounds().hi, glm::vec3(1.0e6f)) << "the lone far vertex counts";
    Hit h;
    const MeshBvh only = bounds_only_mesh_bvh(meshes[0]);
    EXPECT_THROW(
        intersect_closest(only, Ray{glm::vec3(0.0f, 0.0f, -5.0f), glm::vec3(0, 0, 1)}, 0.0f, NB_INF, h),
        Error);
    EXPECT_THROW(intersect_any(only, Ray{glm::vec3(0.0f, 0.0f, -5.0f), glm::vec3(0, 0, 1)}, 0.0f, NB_INF),
                 Error);
}

// A scene with some meshes bounds-only has the TLAS of the full build; a ray that reaches such a mesh
// throws, one that reaches only built meshes is answered as before.
TEST(SceneAccel, BoundsOnlyMeshesKeepTheTlas) {
    std::mt19937 rng(6);
    const Scene s = make_scene(rng);
    const SceneAccel full = build_scene_accel(s);
    const SceneAccel part = build_scene_accel_bounds_only(s, {false, true, true});
    ASSERT_EQ(part.meshes.size(), 3u);
    EXPECT_FALSE(part.meshes[0].bounds_only);
    EXPECT_TRUE(part.meshes[1].bounds_only && part.meshes[2].bounds_only);
    EXPECT_EQ(part.tlas.prim_indices, full.tlas.prim_indices);
    ASSERT_EQ(part.tlas.nodes.size(), full.tlas.nodes.size());
    for (size_t n = 0; n < full.tlas.nodes.size(); ++n) {
        EXPECT_TRUE(same_box(part.tlas.nodes[n].bounds, full.tlas.nodes[n].bounds)) << "node " << n;
        EXPECT_EQ(part.tlas.nodes[n].count, full.tlas.nodes[n].count);
        EXPECT_EQ(part.tlas.nodes[n].first, full.tlas.nodes[n].first);
    }
    for (size_t i = 0; i < s.instances.size(); ++i)
        EXPECT_TRUE(same_box(part.instance_bounds[i], full.instance_bounds[i])) << "instance " << i;
    // Instance 3 (mesh 1) is alone around (0, 3, 1); instance 0 (mesh 0) at the origin, where instance 4
    // (mesh 1) overlaps it.
    SceneHit h;
    EXPECT_THROW(
        intersect_closest(part, Ray{glm::vec3(0.0f, 3.0f, -10.0f), glm::vec3(0, 0, 1)}, 0.0f, NB_INF, h),
        Error);
    const SceneAccel mesh0 = build_scene_accel_bounds_only(s, {true});
    EXPECT_THROW(intersect_any(mesh0, Ray{glm::vec3(0.0f, 0.0f, -10.0f), glm::vec3(0, 0, 1)}, 0.0f, NB_INF),
                 Error);
    const SceneAccel mesh1 = build_scene_accel_bounds_only(s, {false, true});
    // Rays through instance 1 (mesh 0, around (3, 0, 0)) and no mesh-1 instance: the same hits.
    int hits = 0;
    for (int i = 0; i < 15; ++i)
        for (int j = 0; j < 15; ++j) {
            const Ray r{glm::vec3(2.2f + 0.11f * float(i), -0.8f + 0.11f * float(j), -10.0f),
                        glm::vec3(0, 0, 1)};
            SceneHit a, b;
            const bool ha = intersect_closest(mesh1, r, 0.0f, NB_INF, a);
            ASSERT_EQ(ha, intersect_closest(full, r, 0.0f, NB_INF, b)) << i << " " << j;
            if (!ha) continue;
            ++hits;
            EXPECT_EQ(a.t, b.t);
            EXPECT_EQ(a.instance, 1u);
            EXPECT_EQ(a.triangle, b.triangle);
        }
    EXPECT_GT(hits, 20) << "the rays must reach instance 1's triangles";
    EXPECT_TRUE(build_scene_accel_bounds_only(s, {}).meshes[0].bvh.nodes.size() > 1) << "no flags: all built";
}

TEST(SceneAccel, EmptyScene) {
    Scene s;
    SceneAccel a = build_scene_accel(s);
    SceneHit h;
    EXPECT_FALSE(intersect_closest(a, Ray{}, 0.0f, NB_INF, h));
    EXPECT_FALSE(intersect_any(a, Ray{}, 0.0f, NB_INF));
    EXPECT_TRUE(to_gpu_layout(a.tlas).empty());
}

} // namespace
} // namespace nbvh
