// The automatic camera at any scale (issue 12, "Any scale, anywhere"): a 0.1 mm asset and a 100 km one,
// at the origin and far from it, are framed alike (same distance in bounding-sphere radii), every bounds
// corner is inside the image, and orbiting about / dollying towards the target keeps them usable.
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "engine/scene/camera.h"

namespace {

// A box-shaped scene: two triangles spanning the box's diagonal planes, so the world bounds are exactly
// [centre - half, centre + half].
nbvh::Scene box_scene(const glm::vec3& centre, const glm::vec3& half) {
    nbvh::Scene s;
    nbvh::Mesh m;
    const glm::vec3 lo = centre - half, hi = centre + half;
    m.positions = {lo, glm::vec3(hi.x, lo.y, lo.z), hi, glm::vec3(lo.x, hi.y, hi.z)};
    m.normals.assign(4, glm::vec3(0, 0, 1));
    m.indices = {0, 1, 2, 0, 2, 3};
    m.triangle_material = {0, 0};
    s.meshes.push_back(m);
    s.instances.push_back({});
    s.materials.push_back({});
    return s;
}

bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Every corner of `box` projects inside the image of `cam` (vertical fov yfov, aspect w/h), in front of it.
void expect_sees_box(const nbvh::Camera& cam, const nbvh::Aabb& box, float aspect, const std::string& what) {
    const nbvh::CameraBasis b = nbvh::camera_basis(cam);
    const float tan_y = std::tan(0.5f * cam.yfov), tan_x = tan_y * aspect;
    for (int c = 0; c < 8; ++c) {
        const glm::vec3 p((c & 1) ? box.hi.x : box.lo.x, (c & 2) ? box.hi.y : box.lo.y, (c & 4) ? box.hi.z : box.lo.z);
        // In double: the corner minus the eye cancels most digits far from the origin.
        const glm::dvec3 d = glm::dvec3(p) - glm::dvec3(cam.eye);
        const double z = glm::dot(d, glm::dvec3(b.forward));
        ASSERT_GT(z, 0.0) << what << " corner " << c << " behind the camera";
        EXPECT_LE(std::fabs(glm::dot(d, glm::dvec3(b.right))) / z, tan_x * 1.001) << what << " corner " << c;
        EXPECT_LE(std::fabs(glm::dot(d, glm::dvec3(b.up))) / z, tan_y * 1.001) << what << " corner " << c;
    }
}

struct Case {
    const char* name;
    glm::vec3 centre, half;
};

const Case CASES[] = {
    {"1 m at the origin", {0, 0, 0}, {0.5f, 0.3f, 0.4f}},
    {"0.1 mm at the origin", {0, 0, 0}, {0.5e-4f, 0.3e-4f, 0.4e-4f}},
    {"0.1 mm at 2 cm", {0.02f, -0.01f, 0.015f}, {0.5e-4f, 0.3e-4f, 0.4e-4f}},
    {"100 km at the origin", {0, 0, 0}, {0.5e5f, 0.3e5f, 0.4e5f}},
    {"100 km, 3000 km from the origin", {1.0e6f, 2.0e5f, -3.0e6f}, {0.5e5f, 0.3e5f, 0.4e5f}},
};

TEST(CameraScale, AutoFrameIsTheSameAtEveryScaleAndPlace) {
    const float aspect = 16.0f / 9.0f;
    double reference = 0.0; // eye-target distance in bounding-sphere radii, from the 1 m case
    for (const Case& k : CASES) {
        SCOPED_TRACE(k.name);
        const nbvh::Scene s = box_scene(k.centre, k.half);
        const nbvh::Camera cam = nbvh::auto_frame(s, aspect);
        ASSERT_TRUE(finite3(cam.eye) && finite3(cam.target));
        expect_sees_box(cam, s.world_bounds(), aspect, k.name);
        const double radius = glm::length(glm::dvec3(k.half));
        const double ratio = glm::distance(glm::dvec3(cam.eye), glm::dvec3(cam.target)) / radius;
        if (reference == 0.0) reference = ratio;
        // Framed alike: a 0.1 mm asset is not pushed ten times further away by an absolute clamp.
        EXPECT_NEAR(ratio, reference, 1e-3 * reference);
    }
}

TEST(CameraScale, OrbitAndDollyKeepTheSceneInView) {
    const float aspect = 4.0f / 3.0f;
    for (const Case& k : CASES) {
        SCOPED_TRACE(k.name);
        const nbvh::Scene s = box_scene(k.centre, k.half);
        const nbvh::Camera home = nbvh::auto_frame(s, aspect);
        // Orbit: the eye rotated about the target (yaw about +y, then pitch), the scene stays in view.
        for (float yaw : {0.0f, 1.0f, 2.5f, -2.0f})
            for (float pitch : {-1.2f, 0.0f, 0.7f, 1.5f}) {
                const glm::mat4 r = glm::rotate(glm::mat4(1.0f), yaw, glm::vec3(0, 1, 0)) *
                                    glm::rotate(glm::mat4(1.0f), pitch, glm::vec3(1, 0, 0));
                nbvh::Camera c = home;
                c.eye = home.target + glm::vec3(r * glm::vec4(home.eye - home.target, 0.0f));
                ASSERT_TRUE(finite3(c.eye));
                expect_sees_box(c, s.world_bounds(), aspect, "orbit");
            }
        // Dolly towards the target (the viewer's wheel: 10 % per notch), 40 notches = 67x closer: the eye
        // stays distinct from the target and the view still looks at it.
        nbvh::Camera c = home;
        for (int notch = 0; notch < 40; ++notch) {
            c.eye = c.target + 0.9f * (c.eye - c.target);
            ASSERT_NE(c.eye, c.target) << "notch " << notch;
            const nbvh::CameraBasis b = nbvh::camera_basis(c);
            ASSERT_TRUE(finite3(b.forward) && finite3(b.right) && finite3(b.up));
            const glm::dvec3 to_target = glm::normalize(glm::dvec3(c.target) - glm::dvec3(c.eye));
            EXPECT_GT(glm::dot(to_target, glm::dvec3(b.forward)), 0.9999) << "notch " << notch;
        }
    }
}

TEST(CameraScale, PointLikeScenesStayFinite) {
    for (const glm::vec3& p : {glm::vec3(0.0f), glm::vec3(2.0f), glm::vec3(3.0e6f, -1.0e6f, 5.0e5f)}) {
        const nbvh::Camera c = nbvh::auto_frame(box_scene(p, glm::vec3(0.0f)), 1.0f);
        EXPECT_TRUE(finite3(c.eye) && finite3(c.target));
        EXPECT_NE(c.eye, c.target);
    }
}

} // namespace
