// KHR_lights_punctual in the loader (issue 12): types, units, cones and range as the extension defines
// them, placed by their nodes' world transforms (position = node origin, direction = node -z, light
// properties not scaled); invalid lights are skipped or repaired with a warning, never an error.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/core/log.h"
#include "engine/scene/gltf_loader.h"
#include "gltf_test_files.h"
#include "tests/support/test_support.h"

namespace {

namespace fs = std::filesystem;
using nbvh::LightType;
using nbvh::test::quad_gltf;
using nbvh::test::write_gltf;

nbvh::Scene load_quiet(const fs::path& path) {
    nbvh::set_log_level(nbvh::LogLevel::quiet);
    nbvh::Scene s = nbvh::load_gltf(path);
    nbvh::set_log_level(nbvh::LogLevel::info);
    return s;
}

void expect_vec(const glm::vec3& a, const glm::vec3& b, float tol = 1e-5f) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

TEST(GltfLights, PointSpotDirectionalPlacedByTheirNodes) {
    const fs::path dir = nbvh::test::temp_dir("gltf_lights");
    nbvh::test::GltfBuilder b = quad_gltf();
    b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {
        {{"type", "point"},
         {"color", {1.0, 0.5, 0.25}},
         {"intensity", 20.0},
         {"range", 7.5},
         {"name", "bulb"}},
        {{"type", "spot"},
         {"intensity", 100.0},
         {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.5}}}},
        {{"type", "directional"}, {"intensity", 3.0}}};
    // Parent: translate (1, 2, 3), scale 2 (not applied to light properties). Its children: the point light
    // translated by (0, 1, 0) in the parent frame, the spot rotated -90 degrees about x (its -z becomes -y).
    // The directional light hangs at the root, rotated +90 degrees about y (its -z becomes -x).
    const double s = std::sqrt(0.5);
    b.doc["nodes"] = {
        {{"mesh", 0}},
        {{"translation", {1, 2, 3}}, {"scale", {2, 2, 2}}, {"children", {2, 3}}},
        {{"translation", {0, 1, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}},
        {{"rotation", {-s, 0, 0, s}}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}},
        {{"rotation", {0, s, 0, s}}, {"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}}};
    b.doc["scenes"] = {{{"nodes", {0, 1, 4}}}};
    const nbvh::Scene sc = load_quiet(write_gltf(dir / "lights.gltf", b.finish()));
    ASSERT_EQ(sc.lights.size(), 3u);
    const nbvh::PunctualLight& p = sc.lights[0];
    EXPECT_EQ(p.type, LightType::point);
    EXPECT_EQ(p.name, "bulb");
    expect_vec(p.color, {1.0f, 0.5f, 0.25f});
    EXPECT_FLOAT_EQ(p.intensity, 20.0f);
    EXPECT_FLOAT_EQ(p.range, 7.5f) << "range is not scaled by the node";
    expect_vec(p.position, {1.0f, 4.0f, 3.0f}); // (1,2,3) + 2 * (0,1,0)

    const nbvh::PunctualLight& sp = sc.lights[1];
    EXPECT_EQ(sp.type, LightType::spot);
    EXPECT_FLOAT_EQ(sp.inner_cone, 0.2f);
    EXPECT_FLOAT_EQ(sp.outer_cone, 0.5f);
    EXPECT_EQ(sp.range, 0.0f) << "no range: infinite";
    expect_vec(sp.position, {1.0f, 2.0f, 3.0f});
    // Rotation -90 degrees about x maps -z to -y: the spot shines down.
    expect_vec(sp.direction, {0.0f, -1.0f, 0.0f});

    const nbvh::PunctualLight& d = sc.lights[2];
    EXPECT_EQ(d.type, LightType::directional);
    EXPECT_FLOAT_EQ(d.intensity, 3.0f);
    // Rotation +90 degrees about y maps -z to -x.
    expect_vec(d.direction, {-1.0f, 0.0f, 0.0f});
    EXPECT_NEAR(glm::length(d.direction), 1.0f, 1e-6f);
}

TEST(GltfLights, InvalidLightsAreSkippedOrRepairedWithAWarning) {
    const fs::path dir = nbvh::test::temp_dir("gltf_lights_bad");
    nbvh::test::GltfBuilder b = quad_gltf();
    b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {
        {{"type", "area"}},                       // unknown type: skipped
        {{"type", "point"}, {"intensity", -1.0}}, // negative: skipped
        {{"type", "spot"},
         {"spot", {{"innerConeAngle", 0.9}, {"outerConeAngle", 0.3}}}}, // inner >= outer: repaired
        {{"type", "point"}, {"range", -2.0}, {"color", {1, 1}}}};       // bad range, colour: defaults
    nlohmann::json nodes = {{{"mesh", 0}}};
    for (int l : {0, 1, 2, 3, 9})
        nodes.push_back({{"extensions", {{"KHR_lights_punctual", {{"light", l}}}}}});
    nodes.push_back({{"extensions", {{"KHR_lights_punctual", {{"light", "zero"}}}}}});
    b.doc["nodes"] = nodes;
    b.doc["scenes"] = {{{"nodes", {0, 1, 2, 3, 4, 5, 6}}}};
    nbvh::set_log_level(nbvh::LogLevel::warn);
    testing::internal::CaptureStderr();
    const nbvh::Scene sc = nbvh::load_gltf(write_gltf(dir / "bad_lights.gltf", b.finish()));
    const std::string err = testing::internal::GetCapturedStderr();
    nbvh::set_log_level(nbvh::LogLevel::info);
    ASSERT_EQ(sc.lights.size(), 2u) << err;
    EXPECT_EQ(sc.lights[0].type, LightType::spot);
    EXPECT_GT(sc.lights[0].outer_cone, sc.lights[0].inner_cone);
    EXPECT_LE(sc.lights[0].outer_cone, 1.5708f);
    EXPECT_EQ(sc.lights[1].range, 0.0f);
    expect_vec(sc.lights[1].color, {1.0f, 1.0f, 1.0f});
    for (const char* what : {"unknown type", "intensity", "cone angles", "range", "colour", "out of range"})
        EXPECT_NE(err.find(what), std::string::npos) << what << " not warned:\n" << err;
}

} // namespace
