// GPU traversal (passes/traverse.comp on lavapipe, validation on) against the CPU traversal
// (engine/bvh/scene_accel.h) for random rays on real scenes: same hit/miss, instance, triangle and t.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/bvh/scene_accel.h"
#include "engine/render/wavefront.h"
#include "engine/scene/gltf_loader.h"
#include "engine/vk/context.h"
#include "tests/render/test_scenes.h"
#include "tests/support/test_support.h"

namespace nbvh::render {
namespace {

vk::Context make_lavapipe() {
    vk::ContextOptions o;
    o.device = vk::DeviceChoice::cpu;
    o.validation = true;
    return vk::Context(o);
}

// Rays from a sphere around the scene towards random points inside its bounds (most hit), plus
// some in uniformly random directions.
void make_rays(const Aabb& b, size_t n, uint32_t seed, std::vector<glm::vec3>& org, std::vector<glm::vec3>& dir) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const glm::vec3 c = b.center();
    const float r = 0.75f * glm::length(b.extent()) + 1e-3f;
    for (size_t i = 0; i < n; ++i) {
        glm::vec3 d;
        do d = glm::vec3(u(rng), u(rng), u(rng)) * 2.0f - 1.0f; while (glm::dot(d, d) > 1.0f || glm::dot(d, d) < 1e-4f);
        const glm::vec3 o = c + glm::normalize(d) * r;
        glm::vec3 target = b.lo + glm::vec3(u(rng), u(rng), u(rng)) * b.extent();
        glm::vec3 dd = (i % 8 == 7) ? glm::normalize(d) : glm::normalize(target - o);
        org.push_back(o);
        dir.push_back(dd);
    }
}

void compare_with_cpu(const Scene& scene, size_t ray_count, double min_agreement, double min_hits = 0.5,
                      const BvhBuildOptions& blas = default_blas_options()) {
    vk::Context ctx = make_lavapipe();
    const SceneAccel accel = build_scene_accel(scene, blas);
    RenderOptions opt;
    opt.width = 64;
    opt.height = 32;
    WavefrontRenderer renderer(ctx, scene, accel, Environment{}, scene.camera, opt);
    std::vector<glm::vec3> org, dir;
    make_rays(scene.world_bounds(), ray_count, 1234u, org, dir);
    const std::vector<TraceHit> gpu = renderer.trace(org, dir);
    ASSERT_EQ(gpu.size(), ray_count);
    const float scale = glm::length(scene.world_bounds().extent());
    size_t agree = 0, hits = 0;
    for (size_t i = 0; i < ray_count; ++i) {
        SceneHit cpu;
        const bool cpu_hit = intersect_closest(accel, Ray{org[i], dir[i]}, 0.0f, NB_INF, cpu);
        const bool gpu_hit = gpu[i].instance != 0xFFFFFFFFu;
        hits += cpu_hit;
        if (cpu_hit != gpu_hit) continue;
        if (!cpu_hit) { ++agree; continue; }
        // Same triangle, or (ties on shared edges) the same distance.
        const bool same_prim = cpu.instance == gpu[i].instance && cpu.triangle == gpu[i].triangle;
        if (std::abs(cpu.t - gpu[i].t) <= 1e-5f * scale && (same_prim || std::abs(cpu.t - gpu[i].t) <= 1e-6f * scale))
            ++agree;
        if (same_prim) { EXPECT_NEAR(cpu.t, gpu[i].t, 1e-5f * scale) << "ray " << i; }
    }
    EXPECT_GT(double(hits), min_hits * double(ray_count)) << "the test rays should mostly hit";
    EXPECT_GE(double(agree), min_agreement * double(ray_count)) << agree << " of " << ray_count << " agree";
    EXPECT_EQ(ctx.validation_message_count(), 0);
}

TEST(GpuTraversal, MatchesCpuOnQuad) {
    Scene s = test::make_quad_scene();
    s.materials[0].double_sided = true;
    compare_with_cpu(s, 512, 0.999);
}

// Single-sided: rays from behind pass through on both sides (about half of the rays come from behind).
TEST(GpuTraversal, MatchesCpuOnSingleSidedQuad) {
    Scene s = test::make_quad_scene();
    s.materials[0].double_sided = false;
    compare_with_cpu(s, 512, 0.999, 0.3);
}

// Wide-BLAS corners the default build never makes (shared/wide_bvh_node.h): leaves of 16 triangles (the
// most a leaf reference holds) under 4-wide nodes, in two meshes (node references offset by the first
// BLAS) and a rotated instance; the quad's BLAS is one node with one leaf child.
TEST(GpuTraversal, MatchesCpuWithLeavesOfSixteen) {
    Scene s = test::make_quad_scene();
    std::mt19937 rng(77);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    Mesh soup;
    for (uint32_t i = 0; i < 3000; ++i) {
        const glm::vec3 c(u(rng), u(rng), u(rng));
        for (int k = 0; k < 3; ++k) {
            soup.indices.push_back(uint32_t(soup.positions.size()));
            soup.positions.push_back(c + 0.15f * glm::vec3(u(rng), u(rng), u(rng)));
        }
        soup.triangle_material.push_back(0);
    }
    s.meshes.push_back(soup);
    Instance inst;
    inst.mesh = 1;
    s.instances.push_back(inst);
    inst.object_to_world = glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(0.5f, 0.0f, 0.3f)), 0.7f,
                                       glm::vec3(0.3f, 1.0f, 0.2f));
    s.instances.push_back(inst);
    s.materials[0].double_sided = true;
    BvhBuildOptions o = default_blas_options();
    o.max_leaf_size = NB_LEAF_MAX_COUNT;
    o.traversal_cost = 1000.0f; // splitting costs more than 16 triangle tests: full leaves
    const SceneAccel accel = build_scene_accel(s, o);
    uint32_t largest = 0;
    for (const BvhNode& n : accel.meshes[1].bvh.nodes) largest = std::max(largest, n.count);
    ASSERT_EQ(largest, NB_LEAF_MAX_COUNT);
    compare_with_cpu(s, 1024, 0.995, 0.5, o);
}

TEST(GpuTraversal, MatchesCpuOnStanfordBunny) {
    NBVH_REQUIRE_SHARED();
    SceneLoadOptions lo;
    lo.keep_textures = false;
    const Scene s = load_gltf(test::scenes_dir() / "stanford_bunny" / "stanford_bunny.glb", lo);
    compare_with_cpu(s, 2048, 0.995);
}

TEST(GpuTraversal, MatchesCpuOnFlightHelmet) {
    NBVH_REQUIRE_SHARED();
    SceneLoadOptions lo;
    lo.keep_textures = false;
    const Scene s = load_gltf(test::scenes_dir() / "flight_helmet" / "FlightHelmet.gltf", lo);
    compare_with_cpu(s, 2048, 0.995);
}

} // namespace
} // namespace nbvh::render
