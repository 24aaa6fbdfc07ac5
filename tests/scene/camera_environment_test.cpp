// Cameras (--camera parsing, automatic framing, look-at) and environment maps.
#include <cmath>

#include <gtest/gtest.h>

#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/scene/camera.h"
#include "engine/scene/environment.h"
#include "tests/support/test_support.h"

namespace {

bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

TEST(Camera, ParsesValidText) {
    const nbvh::Camera c = nbvh::parse_camera("0, 1, 5, 0,0.5,0, 45");
    EXPECT_EQ(c.eye, glm::vec3(0, 1, 5));
    EXPECT_EQ(c.target, glm::vec3(0, 0.5f, 0));
    EXPECT_NEAR(c.yfov, 45.0f * 3.14159265f / 180.0f, 1e-6f);
}

TEST(Camera, RejectsBadText) {
    for (const char* bad : {"", "1,2,3", "1,2,3,4,5,6,7,8", "1,2,x,4,5,6,45", "1,2,3,4,5,6,0", "1,2,3,4,5,6,180",
                            "1,2,3,1,2,3,45", "nan,0,0,1,1,1,45", "1e99,0,0,1,1,1,45", "1,2,3,4,5,6,45deg"}) {
        EXPECT_THROW(nbvh::parse_camera(bad), nbvh::Error) << bad;
    }
}

TEST(Camera, LookAtIsOrthonormalEvenWhenDegenerate) {
    const nbvh::CameraBasis straight_down = nbvh::look_at({0, 5, 0}, {0, 0, 0});
    const nbvh::CameraBasis same_point = nbvh::look_at({1, 1, 1}, {1, 1, 1});
    for (const nbvh::CameraBasis& b : {straight_down, same_point, nbvh::look_at({0, 0, 3}, {0, 0, 0})}) {
        EXPECT_TRUE(finite3(b.right) && finite3(b.up) && finite3(b.forward));
        EXPECT_NEAR(glm::length(b.right), 1.0f, 1e-5f);
        EXPECT_NEAR(glm::length(b.up), 1.0f, 1e-5f);
        EXPECT_NEAR(glm::dot(b.right, b.up), 0.0f, 1e-5f);
        EXPECT_NEAR(glm::dot(b.forward, b.up), 0.0f, 1e-5f);
    }
    EXPECT_NEAR(straight_down.forward.y, -1.0f, 1e-6f);
}

nbvh::Scene one_triangle_scene(glm::vec3 a, glm::vec3 b, glm::vec3 c) {
    nbvh::Scene s;
    nbvh::Mesh m;
    m.positions = {a, b, c};
    m.normals = {{0, 1, 0}, {0, 1, 0}, {0, 1, 0}};
    m.indices = {0, 1, 2};
    m.triangle_material = {0};
    s.meshes.push_back(m);
    s.instances.push_back({});
    s.materials.push_back({});
    return s;
}

TEST(Camera, AutoFrameSeesTheSceneAndStaysFinite) {
    EXPECT_EQ(nbvh::auto_frame(nbvh::Scene{}, 1.5f).eye, nbvh::Camera{}.eye);
    const nbvh::Scene flat = one_triangle_scene({-1, 0, -1}, {1, 0, -1}, {0, 0, 1});
    const nbvh::Scene point = one_triangle_scene({2, 2, 2}, {2, 2, 2}, {2, 2, 2});
    const nbvh::Scene huge = one_triangle_scene({-1e8f, 0, 0}, {1e8f, 0, 0}, {0, 1e8f, 0});
    for (const nbvh::Scene* s : {&flat, &point, &huge}) {
        const nbvh::Camera c = nbvh::auto_frame(*s, 16.0f / 9.0f);
        EXPECT_TRUE(finite3(c.eye) && finite3(c.target));
        EXPECT_GT(glm::distance(c.eye, c.target), 0.0f);
        EXPECT_EQ(c.target, s->world_bounds().center());
        // Every bounds corner is inside the view cone (half-angle = yfov / 2).
        const nbvh::CameraBasis b = nbvh::camera_basis(c);
        const nbvh::Aabb box = s->world_bounds();
        for (const glm::vec3& p : {box.lo, box.hi}) {
            const glm::vec3 d = p - c.eye;
            EXPECT_LE(std::fabs(glm::dot(d, b.up)) / glm::dot(d, b.forward), std::tan(0.5f * c.yfov) + 1e-4f);
        }
    }
}

TEST(Environment, LoadsSharedHdris) {
    NBVH_REQUIRE_SHARED();
    const auto dir = nbvh::test::scenes_dir() / "hdris";
    const std::pair<const char*, uint32_t> files[] = {{"photo_studio_loft_hall_512x256.hdr", 512},
                                                      {"quarry_01_1k.hdr", 1024},
                                                      {"royal_esplanade_1k.hdr", 1024},
                                                      {"venice_sunset_1k.hdr", 1024}};
    for (const auto& [name, width] : files) {
        const nbvh::Environment env = nbvh::load_environment(dir / name);
        EXPECT_EQ(env.width, width) << name;
        EXPECT_EQ(env.height, width / 2) << name;
        ASSERT_EQ(env.rgb.size(), size_t(env.width) * env.height * 3) << name;
        size_t bad = 0;
        double sum = 0.0;
        for (float v : env.rgb) {
            bad += !std::isfinite(v) || v < 0.0f;
            sum += v;
        }
        EXPECT_EQ(bad, 0u) << name;
        EXPECT_GT(sum, 0.0) << name;
    }
}

TEST(Environment, BadFilesAreClearErrors) {
    EXPECT_THROW(nbvh::load_environment("/nonexistent/sky.hdr"), nbvh::Error);
    EXPECT_THROW(nbvh::load_environment("/nonexistent/sky.png"), nbvh::Error);
    const auto dir = nbvh::test::temp_dir("scene_env");
    const auto junk = dir / "junk.hdr";
    { std::FILE* f = std::fopen(junk.string().c_str(), "wb"); std::fputs("#?RADIANCE\nnot really\n", f); std::fclose(f); }
    EXPECT_THROW(nbvh::load_environment(junk), nbvh::Error);
}

TEST(Environment, DefaultSkyIsFiniteAndBrightestNearTheSun) {
    const nbvh::Environment env = nbvh::default_sky();
    EXPECT_EQ(env.width, 2 * env.height);
    ASSERT_EQ(env.rgb.size(), size_t(env.width) * env.height * 3);
    float max_v = 0.0f;
    for (float v : env.rgb) {
        ASSERT_TRUE(std::isfinite(v) && v >= 0.0f);
        max_v = std::max(max_v, v);
    }
    EXPECT_GT(max_v, 5.0f) << "a sun lobe";
    EXPECT_FALSE(env.empty());
}

} // namespace
