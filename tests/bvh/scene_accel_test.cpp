// Two-level scene acceleration (TLAS over instances) against brute force, with rotated, mirrored,
// non-uniformly scaled and invalid instances.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/bvh/scene_accel.h"
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
