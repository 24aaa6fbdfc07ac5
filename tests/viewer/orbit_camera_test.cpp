// The viewer's camera controller and the node-count -> LoD mapping (no window needed).
#include <gtest/gtest.h>

#include <cmath>

#include "app/viewer/orbit_camera.h"
#include "app/viewer/ui_panel.h"

namespace nbvh::viewer {
namespace {

Camera make_camera(glm::vec3 eye, glm::vec3 target) {
    Camera c;
    c.eye = eye;
    c.target = target;
    c.yfov = 0.7f;
    return c;
}

void expect_near(const glm::vec3& a, const glm::vec3& b, float tol) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

TEST(OrbitCamera, RoundTripsTheStartCamera) {
    const Camera c = make_camera({1.0f, 2.0f, 5.0f}, {0.5f, 0.25f, -1.0f});
    const Camera out = OrbitCamera(c).camera();
    expect_near(out.eye, c.eye, 1e-4f);
    expect_near(out.target, c.target, 1e-6f);
    EXPECT_FLOAT_EQ(out.yfov, c.yfov);
}

TEST(OrbitCamera, OrbitKeepsTargetAndDistance) {
    OrbitCamera cam(make_camera({0.0f, 0.0f, 4.0f}, {0.0f, 0.0f, 0.0f}));
    cam.orbit(360.0f, 0.0f); // 90 degrees of yaw
    const Camera c = cam.camera();
    expect_near(c.target, glm::vec3(0.0f), 1e-6f);
    EXPECT_NEAR(glm::length(c.eye - c.target), 4.0f, 1e-4f);
    EXPECT_NEAR(std::abs(c.eye.x), 4.0f, 1e-3f); // moved from +z to the x axis
    EXPECT_NEAR(c.eye.z, 0.0f, 1e-3f);
}

TEST(OrbitCamera, PitchIsClampedBelowThePoles) {
    OrbitCamera cam(make_camera({0.0f, 0.0f, 4.0f}, {0.0f, 0.0f, 0.0f}));
    cam.orbit(0.0f, 1.0e6f);
    EXPECT_LT(cam.pitch(), 1.5708f);
    const Camera c = cam.camera();
    EXPECT_TRUE(std::isfinite(c.eye.x) && std::isfinite(c.eye.y) && std::isfinite(c.eye.z));
    EXPECT_GT(std::hypot(c.eye.x, c.eye.z), 1e-3f); // not exactly above: look_at stays well defined
}

TEST(OrbitCamera, ZoomNeverPassesTheTarget) {
    OrbitCamera cam(make_camera({0.0f, 0.0f, 2.0f}, {0.0f, 0.0f, 0.0f}));
    cam.zoom(1.0f);
    EXPECT_NEAR(cam.distance(), 1.8f, 1e-5f);
    cam.zoom(1.0e4f);
    EXPECT_GT(cam.distance(), 0.0f);
    EXPECT_GT(cam.camera().eye.z, 0.0f);
    cam.zoom(-2.0f);
    EXPECT_GT(cam.distance(), 0.0f);
}

TEST(OrbitCamera, PanMovesInTheViewPlaneByScreenPixels) {
    OrbitCamera cam(make_camera({0.0f, 0.0f, 4.0f}, {0.0f, 0.0f, 0.0f}));
    const float before = cam.distance();
    cam.pan(-100.0f, 0.0f, 200.0f); // drag left by half the viewport height: the view moves right
    const glm::vec3 t = cam.target();
    const float half_height = 4.0f * std::tan(0.35f);
    EXPECT_NEAR(t.x, half_height, 1e-4f);
    EXPECT_NEAR(t.y, 0.0f, 1e-6f);
    EXPECT_NEAR(t.z, 0.0f, 1e-6f);
    EXPECT_FLOAT_EQ(cam.distance(), before);
}

TEST(OrbitCamera, FlyMovesEyeAndTargetTogetherAndResetRestores) {
    const Camera start = make_camera({0.0f, 1.0f, 4.0f}, {0.0f, 1.0f, 0.0f});
    OrbitCamera cam(start);
    cam.fly(1.0f, 0.0f, 0.0f, 0.5f); // half the orbit distance forward (-z)
    expect_near(cam.target(), glm::vec3(0.0f, 1.0f, -2.0f), 1e-4f);
    EXPECT_NEAR(cam.distance(), 4.0f, 1e-5f);
    cam.reset();
    expect_near(cam.camera().eye, start.eye, 1e-4f);
    expect_near(cam.camera().target, start.target, 1e-6f);
}

TEST(UiPanel, NodeCountPicksTheNearestLod) {
    const std::vector<uint32_t> counts = {1000, 400, 100, 10};
    EXPECT_EQ(lod_for_node_count(counts, 1000), 0);
    EXPECT_EQ(lod_for_node_count(counts, 900), 0);
    EXPECT_EQ(lod_for_node_count(counts, 300), 1);
    EXPECT_EQ(lod_for_node_count(counts, 120), 2);
    EXPECT_EQ(lod_for_node_count(counts, 0), 3);
    EXPECT_EQ(lod_for_node_count({}, 50), 0);
}

} // namespace
} // namespace nbvh::viewer
