// doubleSided: false (issue 12, lavapipe): back faces of single-sided materials are culled for every ray;
// double-sided ones shade their back with the flipped normal; an inverted-hull outline around a sphere
// renders like the sphere alone except at its silhouette.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "engine/bvh/scene_accel.h"
#include "engine/render/wavefront.h"
#include "engine/scene/camera.h"
#include "engine/scene/environment.h"
#include "engine/scene/outline_shells.h"
#include "engine/vk/context.h"
#include "tests/render/test_scenes.h"

namespace nbvh::render {
namespace {

Image render(const Scene& s, const Environment& env, uint32_t size, uint32_t spp,
             uint32_t* shells = nullptr) {
    vk::ContextOptions o;
    o.device = vk::DeviceChoice::cpu;
    o.validation = true;
    vk::Context ctx(o);
    const SceneAccel accel = build_scene_accel(s);
    RenderOptions opt;
    opt.width = opt.height = size;
    opt.spp = spp;
    opt.max_depth = 4;
    opt.seed = 5;
    WavefrontRenderer r(ctx, s, accel, env, s.camera, opt);
    if (shells) *shells = r.scene_data().outline_shells;
    RenderResult res = r.render();
    EXPECT_EQ(ctx.validation_message_count(), 0);
    EXPECT_EQ(res.stats.nonfinite_pixels, 0u);
    return std::move(res.image);
}

float mean_green(const Image& img) {
    double m = 0.0;
    for (size_t i = 0; i < img.pixel_count(); ++i) m += img.data[i * 4 + 1];
    return float(m / double(img.pixel_count()));
}

TEST(BackFaces, SingleSidedQuadSeenFromBehindIsNotThere) {
    Scene s = test::make_quad_scene();
    s.camera.eye = {0.0f, 0.0f, -3.0f}; // behind the quad (it faces +z)
    s.camera.yfov = 0.3f;               // every pixel on the quad
    s.materials[0].base_color = glm::vec4(0.2f, 0.2f, 0.2f, 1.0f);
    const Environment sky = constant_environment(glm::vec3(1.0f));
    const float single = mean_green(render(s, sky, 8, 4));
    EXPECT_FLOAT_EQ(single, 1.0f) << "the sky through the culled back face";
    s.materials[0].double_sided = true;
    const float both = mean_green(render(s, sky, 8, 16));
    // The back face shaded with the flipped normal: a rough grey plane under a white sky (~0.2-0.3).
    EXPECT_GT(both, 0.15f);
    EXPECT_LT(both, 0.4f);
}

// A sphere with outward faces, optionally wrapped in a 6 % larger copy with inward faces and a black
// single-sided material (the inverted-hull outline idiom).
void add_sphere(Scene& s, float radius, uint32_t material, bool inward) {
    Mesh m;
    m.name = inward ? "outline" : "sphere";
    const uint32_t rings = 24, segs = 48;
    for (uint32_t i = 0; i <= rings; ++i)
        for (uint32_t j = 0; j <= segs; ++j) {
            const float th = 3.14159265f * float(i) / rings, ph = 2.0f * 3.14159265f * float(j) / segs;
            const glm::vec3 n(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
            m.positions.push_back(radius * n);
            m.normals.push_back(inward ? -n : n);
        }
    for (uint32_t i = 0; i < rings; ++i)
        for (uint32_t j = 0; j < segs; ++j) {
            const uint32_t a = i * (segs + 1) + j, b = a + 1, c = a + segs + 1, d = c + 1;
            for (glm::uvec3 t : {glm::uvec3(a, b, c), glm::uvec3(b, d, c)}) {
                const glm::vec3 p0 = m.positions[t.x], p1 = m.positions[t.y], p2 = m.positions[t.z];
                const bool out = glm::dot(glm::cross(p1 - p0, p2 - p0), p0 + p1 + p2) > 0.0f;
                if (out == inward) std::swap(t.y, t.z);
                m.indices.insert(m.indices.end(), {t.x, t.y, t.z});
                m.triangle_material.push_back(material);
            }
        }
    s.meshes.push_back(m);
    Instance inst;
    inst.name = m.name;
    inst.mesh = uint32_t(s.meshes.size() - 1);
    s.instances.push_back(inst);
}

Scene sphere_scene(bool outline) {
    Scene s;
    Material grey;
    grey.base_color = glm::vec4(0.7f, 0.5f, 0.3f, 1.0f);
    grey.metallic = 0.0f;
    grey.roughness = 0.6f;
    Material black;
    black.base_color = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
    black.metallic = 0.0f;
    black.roughness = 1.0f;
    s.materials = {grey, black};
    add_sphere(s, 1.0f, 0, false);
    if (outline) add_sphere(s, 1.06f, 1, true);
    s.camera.eye = {0.0f, 0.5f, 4.0f};
    s.camera.target = {0.0f, 0.0f, 0.0f};
    s.camera.yfov = 0.7f;
    s.has_camera = true;
    return s;
}

TEST(BackFaces, InvertedHullIsFoundAndRoomsAreNot) {
    const Scene s = sphere_scene(true);
    const std::vector<bool> shells = find_outline_shells(s);
    ASSERT_EQ(shells.size(), 2u);
    EXPECT_FALSE(shells[0]);
    EXPECT_TRUE(shells[1]);
    EXPECT_LT(facing_score(s.meshes[1]), -0.9f);
    EXPECT_GT(facing_score(s.meshes[0]), 0.9f);
    // An inside-out room (a big inward sphere) around a small object is a room, not an outline.
    Scene room = sphere_scene(false);
    add_sphere(room, 5.0f, 1, true);
    EXPECT_FALSE(find_outline_shells(room)[1]);
    // A double-sided hull is drawn from both sides by viewers too: not an outline.
    Scene two = sphere_scene(true);
    two.materials[1].double_sided = true;
    EXPECT_FALSE(find_outline_shells(two)[1]);
}

// Acceptance (issue 12): the outlined sphere renders like the sphere alone except at its silhouette. The
// shell is invisible to every ray but camera rays, and camera rays pass its back faces, so away from the
// rim between the two silhouettes the two images are identical (same seed, same paths).
TEST(BackFaces, InvertedHullOutlineRendersLikeTheSphereAloneExceptAtItsSilhouette) {
    const uint32_t size = 64;
    const Environment sky = default_sky();
    uint32_t shells = 0;
    const Image alone = render(sphere_scene(false), sky, size, 16);
    const Image outlined = render(sphere_scene(true), sky, size, 16, &shells);
    EXPECT_EQ(shells, 1u);
    // Project each pixel's ray onto the sphere's centre: the distance of the ray from the centre (world
    // units) says whether it meets the sphere (< 1), the rim (1 .. 1.06) or neither.
    const Scene s = sphere_scene(false);
    const CameraBasis b = camera_basis(s.camera);
    const float t = std::tan(0.5f * s.camera.yfov);
    uint32_t same = 0, compared = 0, rim = 0;
    double rim_alone = 0.0, rim_outlined = 0.0, max_diff = 0.0;
    for (uint32_t y = 0; y < size; ++y)
        for (uint32_t x = 0; x < size; ++x) {
            // Distances of the pixel's corners (jitter covers the whole pixel).
            float dmin = 1e9f, dmax = 0.0f;
            for (int c = 0; c < 4; ++c) {
                const float px = float(x) + float(c & 1), py = float(y) + float(c >> 1);
                const glm::vec3 d = glm::normalize(b.forward + (2.0f * px / size - 1.0f) * t * b.right +
                                                   (1.0f - 2.0f * py / size) * t * b.up);
                const glm::vec3 to_c = -s.camera.eye;
                const float dist = glm::length(to_c - d * glm::dot(to_c, d));
                dmin = std::min(dmin, dist);
                dmax = std::max(dmax, dist);
            }
            const float* a = alone.at(int(x), int(y));
            const float* o = outlined.at(int(x), int(y));
            if (dmin > 1.0f && dmax < 1.06f) { // wholly on the rim: the outline shows
                ++rim;
                rim_alone += a[1];
                rim_outlined += o[1];
            }
            if (dmax < 1.0f || dmin > 1.06f) { // wholly on the sphere or wholly outside the outline
                ++compared;
                const double diff = std::abs(a[0] - o[0]) + std::abs(a[1] - o[1]) + std::abs(a[2] - o[2]);
                max_diff = std::max(max_diff, diff);
                same += diff == 0.0;
            }
        }
    std::printf("  %u pixels compared, %u identical, max |difference| %.3g; rim: %u pixels, mean %.4f "
                "(sphere alone: %.4f)\n",
                compared, same, max_diff, rim, rim ? rim_outlined / rim : 0.0, rim ? rim_alone / rim : 0.0);
    EXPECT_GT(compared, size * size / 2);
    EXPECT_EQ(same, compared) << "the sphere and the background away from the rim are unchanged";
    ASSERT_GT(rim, 20u);
    EXPECT_LT(rim_outlined, 0.2 * rim_alone) << "the rim is dark: the outline";
}

} // namespace
} // namespace nbvh::render
