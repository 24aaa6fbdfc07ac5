// CPU packing of the scene for the shaders: BVH references, lights and their cdf, environment table.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/bvh/scene_accel.h"
#include "engine/render/environment_sampler.h"
#include "engine/render/gpu_scene.h"
#include "tests/render/test_scenes.h"

namespace nbvh::render {
namespace {

TEST(GpuScene, PacksQuadWithInstancesInTlasOrder) {
    Scene s = test::make_quad_scene();
    Instance second = s.instances[0];
    second.object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(3, 0, 0));
    s.instances.push_back(second);
    const SceneAccel accel = build_scene_accel(s);
    const GpuSceneData d = pack_scene(s, accel, Environment{});
    ASSERT_EQ(d.instances.size(), 2u);
    ASSERT_EQ(d.triangles.size(), 2u);
    EXPECT_EQ(d.instance_to_scene.size(), 2u);
    for (size_t i = 0; i < 2; ++i) {
        const uint32_t si = d.instance_to_scene[i];
        EXPECT_FLOAT_EQ(d.instances[i].object_to_world[0].w, si == 1 ? 3.0f : 0.0f);
    }
    // Every interior reference points inside the BLAS array.
    for (const GpuWideNode& n : d.blas_nodes)
        for (uint32_t ref : {n.child0, n.child1, n.child2, n.child3})
            if (!nb_is_leaf(ref) && ref != NB_CHILD_NONE) { EXPECT_LT(ref, d.blas_nodes.size()); }
    // The quad's two triangles are one leaf: its BLAS root is a 4-wide node with that one child.
    ASSERT_EQ(d.blas_nodes.size(), 1u);
    EXPECT_EQ(d.blas_nodes[0].child0, nb_make_leaf(0, 2));
    EXPECT_EQ(d.blas_nodes[0].child1, NB_CHILD_NONE);
    EXPECT_EQ(d.light_total_power, 0.0f);
}

TEST(GpuScene, EmissiveTrianglesBecomePowerWeightedLights) {
    Scene s = test::make_quad_scene();
    s.materials[0].emissive = glm::vec3(1.0f);
    s.instances[0].object_to_world = glm::scale(glm::mat4(1.0f), glm::vec3(2.0f)); // area x4
    const SceneAccel accel = build_scene_accel(s);
    const GpuSceneData d = pack_scene(s, accel, Environment{});
    ASSERT_EQ(d.lights.size(), 2u);
    EXPECT_NEAR(d.lights[0].area + d.lights[1].area, 16.0f, 1e-4f); // 2x2 quad scaled by 2
    EXPECT_NEAR(d.light_total_power, 16.0f, 1e-3f);                // luminance(1,1,1) = 1
    EXPECT_EQ(d.emissive_light_count, 2u);
    EXPECT_EQ(d.punctual_light_count, 0u);
    ASSERT_EQ(d.light_cdf.size(), 4u); // 3 emissive entries, then the (empty) punctual cdf's single 0
    EXPECT_FLOAT_EQ(d.light_cdf[0], 0.0f);
    EXPECT_NEAR(d.light_cdf[1], 0.5f, 1e-5f);
    EXPECT_FLOAT_EQ(d.light_cdf[2], 1.0f);
    for (const GpuLight& l : d.lights) {
        EXPECT_EQ(l.kind, NB_LIGHT_TRIANGLE);
        EXPECT_EQ(l.side, 1.0f) << "single-sided: emits from its front face";
    }
    // A mirroring instance turns the world-space winding around; a double-sided material emits both ways.
    s.instances[0].object_to_world = glm::scale(glm::mat4(1.0f), glm::vec3(-1.0f, 1.0f, 1.0f));
    const GpuSceneData m = pack_scene(s, build_scene_accel(s), Environment{});
    EXPECT_EQ(m.lights[0].side, -1.0f);
    s.materials[0].double_sided = true;
    const GpuSceneData t = pack_scene(s, build_scene_accel(s), Environment{});
    EXPECT_EQ(t.lights[0].side, 0.0f);
}

// KHR_lights_punctual lights follow the emissive triangles, with their own power cdf after the emissive one:
// point 4 pi I, spot 2 pi I (1 - (cos inner + cos outer) / 2), directional pi r^2 E (r: half the scene diagonal).
TEST(GpuScene, PunctualLightsFollowTheEmissiveTrianglesWithAPowerCdf) {
    Scene s = test::make_quad_scene();
    s.materials[0].emissive = glm::vec3(1.0f);
    PunctualLight point, spot, sun, off;
    point.intensity = 2.0f;
    point.position = {0, 0, 1};
    point.range = 5.0f;
    spot.type = LightType::spot;
    spot.intensity = 4.0f;
    spot.color = {1, 0, 0};
    spot.inner_cone = 0.0f;
    spot.outer_cone = 3.14159265f / 3.0f; // cos = 0.5
    spot.direction = {0, 0, -1};
    sun.type = LightType::directional;
    sun.intensity = 1.0f;
    sun.direction = {0, -1, 0};
    off.intensity = 0.0f; // no power: not packed
    s.lights = {point, off, spot, sun};
    const GpuSceneData d = pack_scene(s, build_scene_accel(s), Environment{});
    ASSERT_EQ(d.emissive_light_count, 2u);
    ASSERT_EQ(d.punctual_light_count, 3u);
    ASSERT_EQ(d.lights.size(), 5u);
    const GpuLight& p = d.lights[2];
    const GpuLight& sp = d.lights[3];
    const GpuLight& sn = d.lights[4];
    EXPECT_EQ(p.kind, NB_LIGHT_POINT);
    EXPECT_EQ(sp.kind, NB_LIGHT_SPOT);
    EXPECT_EQ(sn.kind, NB_LIGHT_DIRECTIONAL);
    EXPECT_FLOAT_EQ(p.area, 5.0f) << "range";
    EXPECT_FLOAT_EQ(p.p2.x, 2.0f);
    EXPECT_FLOAT_EQ(p.spot_scale, 0.0f);
    EXPECT_FLOAT_EQ(p.spot_offset, 1.0f);
    // Spot: clamp(cos * scale + offset) is 1 at cos_inner = 1, 0 at cos_outer = 0.5.
    EXPECT_NEAR(1.0f * sp.spot_scale + sp.spot_offset, 1.0f, 1e-5f);
    EXPECT_NEAR(0.5f * sp.spot_scale + sp.spot_offset, 0.0f, 1e-5f);
    EXPECT_FLOAT_EQ(sn.p1.y, -1.0f);
    // Powers: point 4 pi 2; spot 2 pi luminance(4, 0, 0) (1 - 0.75); sun pi r^2 (r^2 = 8/4 = 2 for the 2x2 quad).
    const double pp = 4.0 * 3.14159265 * 2.0, ps = 2.0 * 3.14159265 * 4.0 * 0.2126 * 0.25, pd = 3.14159265 * 2.0;
    const double total = pp + ps + pd;
    ASSERT_EQ(d.light_cdf.size(), 3u + 4u);
    EXPECT_FLOAT_EQ(d.light_cdf[3], 0.0f);
    EXPECT_NEAR(d.light_cdf[4], pp / total, 1e-5);
    EXPECT_NEAR(d.light_cdf[5], (pp + ps) / total, 1e-5);
    EXPECT_FLOAT_EQ(d.light_cdf[6], 1.0f);
}

// Mean of every texel's density (1 for a valid table); each density must be finite.
double mean_density(const EnvironmentTable& t) {
    double mean = 0.0;
    for (uint32_t y = 0; y < t.height; ++y)
        for (uint32_t x = 0; x < t.width; ++x) {
            const float d = environment_density(t, x, y);
            EXPECT_TRUE(std::isfinite(d)) << x << "," << y;
            mean += d;
        }
    return mean / (double(t.width) * t.height);
}

TEST(EnvironmentTable, CdfsAreMonotoneAndDensityAveragesToOne) {
    Environment env;
    env.width = 16;
    env.height = 8;
    env.rgb.resize(16 * 8 * 3);
    for (size_t i = 0; i < env.rgb.size(); ++i) env.rgb[i] = float((i * 7919) % 13) * 0.1f;
    env.rgb[5] = NAN; // bad texel reads as 0
    const EnvironmentTable t = build_environment_table(env);
    const float* marginal = t.data.data() + 16 * 8 * 4; // after the rgba texels
    for (uint32_t y = 0; y < 8; ++y) EXPECT_LE(marginal[y], marginal[y + 1]);
    EXPECT_FLOAT_EQ(marginal[8], 1.0f);
    EXPECT_NEAR(mean_density(t), 1.0, 1e-4);
}

// The shader reads the map bilinearly, so a texel's density is the mean of that bilinear function over it:
// (1/8, 3/4, 1/8) of itself and its neighbours per axis, u wrapping across the seam, v clamped at the poles.
TEST(EnvironmentTable, DensityIsTheBilinearMeanOfEachTexel) {
    Environment env;
    env.width = 8;
    env.height = 4;
    env.rgb.assign(8 * 4 * 3, 0.0f);
    auto set = [&](uint32_t x, uint32_t y) { for (int c = 0; c < 3; ++c) env.rgb[(size_t(y) * 8 + x) * 3 + c] = 1.0f; };
    set(0, 1); // on the seam
    set(4, 0); // on the pole row
    const EnvironmentTable t = build_environment_table(env);
    const auto st = [](uint32_t y) { return float(std::sin(3.14159265358979 * (y + 0.5) / 4.0)); };
    const float k = environment_density(t, 0, 1) / (0.75f * 0.75f * st(1)); // the common scale
    EXPECT_GT(k, 0.0f);
    EXPECT_NEAR(environment_density(t, 7, 1), k * 0.125f * 0.75f * st(1), 1e-5f) << "u wraps";
    EXPECT_NEAR(environment_density(t, 1, 1), k * 0.125f * 0.75f * st(1), 1e-5f);
    EXPECT_NEAR(environment_density(t, 7, 2), k * 0.125f * 0.125f * st(2), 1e-5f);
    EXPECT_NEAR(environment_density(t, 2, 1), 0.0f, 1e-7f) << "two texels away: untouched";
    EXPECT_NEAR(environment_density(t, 4, 0), k * 0.75f * (0.75f + 0.125f) * st(0), 1e-5f) << "v clamps at the pole";
    EXPECT_NEAR(environment_density(t, 4, 1), k * 0.75f * 0.125f * st(1), 1e-5f);
    EXPECT_NEAR(mean_density(t), 1.0, 1e-5);
}

// A map whose table would not fit one storage binding is halved (2x2 box averages) until it does, instead
// of failing the render (a 4096x2048 HDRI on lavapipe's 128 MiB binding).
TEST(EnvironmentTable, LargeMapsAreHalvedToFitTheBinding) {
    Environment env;
    env.width = 64;
    env.height = 32;
    env.rgb.resize(64 * 32 * 3);
    for (uint32_t y = 0; y < 32; ++y)
        for (uint32_t x = 0; x < 64; ++x)
            for (int c = 0; c < 3; ++c) env.rgb[(size_t(y) * 64 + x) * 3 + c] = float(x + 64 * y + c);
    const EnvironmentTable full = build_environment_table(env);
    EXPECT_EQ(full.width, 64u);
    EXPECT_EQ(full.halvings, 0u);
    EXPECT_EQ(uint64_t(full.data.size()) * 4, environment_table_bytes(64, 32));
    const uint64_t budget = environment_table_bytes(16, 8);
    const EnvironmentTable t = build_environment_table(env, budget);
    EXPECT_EQ(t.width, 16u);
    EXPECT_EQ(t.height, 8u);
    EXPECT_EQ(t.halvings, 2u);
    EXPECT_LE(uint64_t(t.data.size()) * 4, budget);
    // Texel (0, 0) is the mean of the source's 4x4 block; channel 0: x + 64 y over x, y in 0..3.
    EXPECT_NEAR(t.data[0], (1.5f + 64.0f * 1.5f), 1e-3f);
    EXPECT_NEAR(mean_density(t), 1.0, 1e-5);
}

TEST(EnvironmentTable, ConstantEnvironmentIsOneTexel) {
    Environment env;
    env.constant = glm::vec3(0.5f);
    const EnvironmentTable t = build_environment_table(env);
    EXPECT_EQ(t.width, 1u);
    EXPECT_EQ(t.height, 1u);
    EXPECT_NEAR(environment_density(t, 0, 0), 1.0f, 1e-5f);
}

} // namespace
} // namespace nbvh::render
