// KHR_lights_punctual through next-event estimation, against closed forms (issue 12, lavapipe): a Lambert +
// GGX plane lit by one point, spot or directional light and nothing else. With one delta light and no
// environment every NEE sample picks that light (probability 1) and the continuation ray escapes into
// black, so a pixel's radiance is f(wo, wi) cos(theta_i) E_light averaged over the pixel: the only noise
// is the random position inside the pixel, which the expected value averages on an 8x8 grid.
//   point:        E = I / d^2                       (candela -> irradiance at normal incidence)
//   spot:         E = I / d^2 * clamp(cos * s + o)^2 (s = 1 / (cos_inner - cos_outer), o = -cos_outer s)
//   directional:  E = illuminance (lux)
//   range:        E *= clamp(1 - (d / range)^4, 0, 1)^2
// f comes from the shared BSDF functions (shared/sampling.h: diffuse base / pi + Schlick-GGX specular), so
// what is checked is the light's irradiance and its placement, not the BSDF. The last two tests check that
// the next-event strategies add up (environment + punctual light, environment + emissive quad).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>

#include "engine/bvh/scene_accel.h"
#include "engine/render/wavefront.h"
#include "engine/scene/camera.h"
#include "engine/scene/environment.h"
#include "engine/vk/context.h"
#include "shaders/shared/sampling.h"
#include "tests/render/test_scenes.h"

namespace nbvh::render {
namespace {

constexpr uint32_t SIZE = 32;       // image side (pixels)
constexpr float VIEW_HEIGHT = 4.0f; // the camera looks straight down from (0, 0, 4)
constexpr float HALF_VIEW = 2.0f;   // ... and sees [-2, 2]^2 of the plane z = 0

// A 10 m grey plane at z = 0 facing +z (rough dielectric), seen from straight above.
Scene lit_plane(const PunctualLight& light) {
    Scene s = test::make_quad_scene();
    for (glm::vec3& p : s.meshes[0].positions) p *= 5.0f;
    s.materials[0].roughness = 1.0f;
    s.camera.eye = {0.0f, 0.0f, VIEW_HEIGHT};
    s.camera.target = {0.0f, 0.0f, 0.0f};
    s.camera.up = {0.0f, 1.0f, 0.0f};
    s.camera.yfov = 2.0f * std::atan(HALF_VIEW / VIEW_HEIGHT);
    s.lights = {light};
    return s;
}

struct Rendered {
    Image image;
    RenderStats stats;
    int validation = 0;
};

Rendered render(const Scene& s, const Environment& env, uint32_t spp, uint32_t max_depth = 2) {
    vk::ContextOptions o;
    o.device = vk::DeviceChoice::cpu;
    o.validation = true;
    vk::Context ctx(o);
    const SceneAccel accel = build_scene_accel(s);
    RenderOptions opt;
    opt.width = opt.height = SIZE;
    opt.spp = spp;
    opt.max_depth = max_depth;
    opt.seed = 11;
    WavefrontRenderer r(ctx, s, accel, env, s.camera, opt);
    EXPECT_TRUE(r.features().punctual || s.lights.empty());
    RenderResult res = r.render();
    return Rendered{std::move(res.image), res.stats, ctx.validation_message_count()};
}

// The plane point seen through image position (px, py) (pixels, continuous), as camera_rays.comp does.
glm::vec3 plane_point(const Camera& cam, float px, float py) {
    const CameraBasis b = camera_basis(cam);
    const float t = std::tan(0.5f * cam.yfov);
    const float sx = (2.0f * px / float(SIZE) - 1.0f) * t;
    const float sy = (1.0f - 2.0f * py / float(SIZE)) * t;
    const glm::vec3 d = glm::normalize(b.forward + sx * b.right + sy * b.up);
    return cam.eye + d * (-cam.eye.z / d.z);
}

// Green-channel radiance towards the camera of the plane's material lit from wi with irradiance e at normal
// incidence (f cos(theta_i) e), as lib/material.glsl nb_bsdf_eval computes it.
float reflected(const Scene& s, const glm::vec3& p, const glm::vec3& wi, float e) {
    const Material& m = s.materials[0];
    const glm::vec3 n(0.0f, 0.0f, 1.0f), wo = glm::normalize(s.camera.eye - p);
    const float n_dot_l = glm::dot(n, wi), n_dot_v = glm::dot(n, wo);
    if (n_dot_l <= 0.0f || n_dot_v <= 0.0f) return 0.0f;
    const glm::vec3 h = glm::normalize(wo + wi);
    const float alpha = nb_ggx_alpha(m.roughness);
    const float f0 = 0.04f * (1.0f - m.metallic) + m.base_color.y * m.metallic;
    const float spec = nb_fresnel_schlick(glm::vec3(f0), glm::dot(wo, h)).y *
                       nb_ggx_d(glm::dot(n, h), alpha) * nb_ggx_v(n_dot_l, n_dot_v, alpha);
    const float diff = m.base_color.y * (1.0f - m.metallic) / NB_PI;
    return (spec + diff) * n_dot_l * e;
}

// Expected green radiance of a point light (spot included) at plane point p, KHR_lights_punctual falloffs.
float punctual_radiance(const Scene& s, const PunctualLight& l, const glm::vec3& p) {
    if (l.type == LightType::directional) return reflected(s, p, -l.direction, l.intensity * l.color.y);
    const glm::vec3 d = l.position - p;
    const float dist = glm::length(d);
    const glm::vec3 wi = d / dist;
    float e = l.intensity * l.color.y / (dist * dist);
    if (l.range > 0.0f) {
        const float r = dist / l.range, w = std::clamp(1.0f - r * r * r * r, 0.0f, 1.0f);
        e *= w * w;
    }
    if (l.type == LightType::spot) {
        const float co = std::cos(l.outer_cone), ci = std::cos(l.inner_cone);
        const float scale = 1.0f / std::max(1e-3f, ci - co);
        const float a = std::clamp(glm::dot(l.direction, -wi) * scale - co * scale, 0.0f, 1.0f);
        e *= a * a;
    }
    return reflected(s, p, wi, e);
}

// The pixel's expected value: the radiance averaged over its area (8x8 grid).
float pixel_expected(const Scene& s, uint32_t x, uint32_t y,
                     const std::function<float(const glm::vec3&)>& radiance) {
    double sum = 0.0;
    for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i)
            sum +=
                radiance(plane_point(s.camera, float(x) + (i + 0.5f) / 8.0f, float(y) + (j + 0.5f) / 8.0f));
    return float(sum / 64.0);
}

// Per-pixel errors relative to the brightest expected pixel (edges of cones and ranges are steep: a pixel
// half inside has a jitter noise of about half its value / sqrt(spp)), and the image sums.
struct Comparison {
    double max_err = 0.0, mean_err = 0.0, expected_sum = 0.0, measured_sum = 0.0;
    uint32_t dark_pixels = 0, dark_pixels_lit = 0; // expected 0 over the whole pixel / and rendered > 0
};

Comparison compare(const Scene& s, const Image& img, const std::function<float(const glm::vec3&)>& radiance) {
    Comparison c;
    std::vector<float> expected(SIZE * SIZE);
    float peak = 0.0f;
    for (uint32_t y = 0; y < SIZE; ++y)
        for (uint32_t x = 0; x < SIZE; ++x) {
            expected[y * SIZE + x] = pixel_expected(s, x, y, radiance);
            peak = std::max(peak, expected[y * SIZE + x]);
        }
    for (uint32_t y = 0; y < SIZE; ++y)
        for (uint32_t x = 0; x < SIZE; ++x) {
            const float e = expected[y * SIZE + x], got = img.at(int(x), int(y))[1];
            c.expected_sum += e;
            c.measured_sum += got;
            // "Dark": no light anywhere near the pixel (its neighbours' grids see none either).
            bool dark = true;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int nx = std::clamp(int(x) + dx, 0, int(SIZE) - 1),
                              ny = std::clamp(int(y) + dy, 0, int(SIZE) - 1);
                    dark = dark && expected[size_t(ny) * SIZE + size_t(nx)] == 0.0f;
                }
            if (dark) {
                ++c.dark_pixels;
                c.dark_pixels_lit += got > 0.0f;
            }
            const double err = std::abs(double(got) - e) / peak;
            c.max_err = std::max(c.max_err, err);
            c.mean_err += err;
        }
    c.mean_err /= double(SIZE * SIZE);
    std::printf(
        "  per-pixel error vs the closed form: mean %.5f, max %.5f of the peak; image sum ratio %.5f\n",
        c.mean_err, c.max_err, c.measured_sum / c.expected_sum);
    return c;
}

TEST(PunctualLights, PointLightIrradianceIsIntensityOverDistanceSquared) {
    PunctualLight l;
    l.type = LightType::point;
    l.intensity = 3.0f;
    l.color = {1.0f, 0.8f, 0.6f};
    l.position = {0.5f, 0.3f, 1.0f};
    const Scene s = lit_plane(l);
    const Rendered r = render(s, Environment{}, 64);
    EXPECT_EQ(r.validation, 0);
    EXPECT_EQ(r.stats.nonfinite_pixels, 0u);
    const Comparison c = compare(s, r.image, [&](const glm::vec3& p) { return punctual_radiance(s, l, p); });
    EXPECT_LT(c.mean_err, 0.002) << "mean error per pixel, relative to the peak";
    EXPECT_LT(c.max_err, 0.02) << "worst pixel (footprint noise of 64 jittered samples near the light)";
    EXPECT_NEAR(c.measured_sum / c.expected_sum, 1.0, 0.002);
}

TEST(PunctualLights, RangeWindowsThePointLightToZero) {
    PunctualLight l;
    l.intensity = 2.0f;
    l.position = {0.0f, 0.0f, 0.8f};
    l.range = 1.6f; // reaches the plane out to sqrt(1.6^2 - 0.8^2) = 1.39 m from the centre
    const Scene s = lit_plane(l);
    const Rendered r = render(s, Environment{}, 64);
    const Comparison c = compare(s, r.image, [&](const glm::vec3& p) { return punctual_radiance(s, l, p); });
    EXPECT_GT(c.dark_pixels, 200u) << "the corners are out of range";
    EXPECT_EQ(c.dark_pixels_lit, 0u) << "nothing beyond the range";
    EXPECT_LT(c.mean_err, 0.002);
    EXPECT_LT(c.max_err, 0.03);
    EXPECT_NEAR(c.measured_sum / c.expected_sum, 1.0, 0.005);
}

// A spot light pointing straight down from 2 m: full intensity inside the inner cone (radius 2 tan 0.25 =
// 0.51 m on the plane), the smooth falloff out to the outer cone (2 tan 0.5 = 1.09 m), black beyond.
TEST(PunctualLights, SpotLightConeEdgeFollowsTheSmoothFalloff) {
    PunctualLight l;
    l.type = LightType::spot;
    l.intensity = 5.0f;
    l.position = {0.2f, -0.1f, 2.0f};
    l.direction = {0.0f, 0.0f, -1.0f};
    l.inner_cone = 0.25f;
    l.outer_cone = 0.5f;
    const Scene s = lit_plane(l);
    const Rendered r = render(s, Environment{}, 64);
    EXPECT_EQ(r.validation, 0);
    const Comparison c = compare(s, r.image, [&](const glm::vec3& p) { return punctual_radiance(s, l, p); });
    EXPECT_GT(c.dark_pixels, 500u) << "outside the outer cone";
    EXPECT_EQ(c.dark_pixels_lit, 0u) << "no light outside the outer cone";
    EXPECT_LT(c.mean_err, 0.003);
    EXPECT_LT(c.max_err, 0.05) << "pixels on the steep part of the cone edge";
    EXPECT_NEAR(c.measured_sum / c.expected_sum, 1.0, 0.005);
    // The cone edge, along a row through the spot's axis: pixels inside the inner cone are as bright as
    // the formula's plateau, those in the falloff band follow the smooth curve, and beyond is black.
    const uint32_t row = uint32_t((0.5f - l.position.y / (2.0f * HALF_VIEW)) * SIZE);
    int plateau = 0, band = 0, beyond = 0;
    for (uint32_t x = 0; x < SIZE; ++x) {
        const glm::vec3 p = plane_point(s.camera, float(x) + 0.5f, float(row) + 0.5f);
        const float rad = glm::length(glm::vec2(p - l.position));
        const float expected =
            pixel_expected(s, x, row, [&](const glm::vec3& q) { return punctual_radiance(s, l, q); });
        const float got = r.image.at(int(x), int(row))[1];
        if (rad < 0.35f) {
            ++plateau;
            EXPECT_NEAR(got, expected, 0.01f * expected) << "x " << x << " r " << rad;
        } else if (rad > 0.65f && rad < 0.95f) {
            ++band;
            EXPECT_NEAR(got, expected, 0.1f * expected + 1e-3f) << "x " << x << " r " << rad;
        } else if (rad > 1.25f) {
            ++beyond;
            EXPECT_EQ(got, 0.0f) << "x " << x << " r " << rad;
        }
    }
    EXPECT_GE(plateau, 4);
    EXPECT_GE(band, 4);
    EXPECT_GE(beyond, 4);
}

TEST(PunctualLights, DirectionalLightGivesIlluminanceTimesCosine) {
    PunctualLight l;
    l.type = LightType::directional;
    l.intensity = 2.0f;
    l.direction = glm::normalize(glm::vec3(0.3f, -0.2f, -1.0f));
    l.position = {100.0f, 100.0f, 100.0f}; // ignored
    const Scene s = lit_plane(l);
    const Rendered r = render(s, Environment{}, 16);
    const Comparison c = compare(s, r.image, [&](const glm::vec3& p) { return punctual_radiance(s, l, p); });
    EXPECT_EQ(c.dark_pixels, 0u);
    EXPECT_LT(c.max_err, 0.01);
    EXPECT_NEAR(c.measured_sum / c.expected_sum, 1.0, 0.002);
}

// Shadow rays: a small occluder between a point light and the plane casts a shadow (the shadow pass runs
// for scenes lit only by punctual lights).
TEST(PunctualLights, OccluderCastsAShadow) {
    PunctualLight l;
    l.intensity = 3.0f;
    l.position = {0.0f, 0.0f, 2.0f};
    Scene s = lit_plane(l);
    Mesh blocker = test::make_quad_scene().meshes[0];
    for (glm::vec3& p : blocker.positions) p = p * 0.2f + glm::vec3(0.0f, 0.0f, 1.5f);
    s.meshes.push_back(blocker);
    Instance bi;
    bi.mesh = 1;
    s.instances.push_back(bi);
    s.materials[0].double_sided = true; // the blocker is seen from below by the shadow rays
    const Rendered r = render(s, Environment{}, 8);
    // The 0.4 m blocker half-way between the light and z = 1 shadows |x|, |y| < 0.8 m; the camera sees the
    // blocker itself up to 0.2 * 4 / 2.5 = 0.32 m. Pixel 20 of the middle row spans x = 0.5 .. 0.625 m.
    const float shadowed = r.image.at(20, int(SIZE / 2))[1];
    const float open = r.image.at(int(SIZE - 3), int(SIZE / 2))[1];
    EXPECT_EQ(shadowed, 0.0f);
    EXPECT_GT(open, 0.0f);
    EXPECT_GT(r.stats.rays_shadow, 0u);
}

// With an environment as well, the NEE strategies split (environment / punctual): the estimator stays
// unbiased, so the image is the sum of the two lights' images.
TEST(PunctualLights, EnvironmentPlusLightIsTheSumOfBoth) {
    PunctualLight l;
    l.intensity = 1.5f;
    l.position = {0.3f, 0.2f, 1.2f};
    Scene s = lit_plane(l);
    const Environment sky = constant_environment(glm::vec3(0.5f));
    const Rendered both = render(s, sky, 64, 3);
    Scene no_light = s;
    no_light.lights.clear();
    const Rendered env_only = render(no_light, sky, 64, 3);
    const Rendered light_only = render(s, Environment{}, 64, 3);
    double a = 0.0, b = 0.0;
    for (size_t i = 0; i < both.image.pixel_count(); ++i) {
        a += both.image.data[i * 4 + 1];
        b += env_only.image.data[i * 4 + 1] + light_only.image.data[i * 4 + 1];
    }
    std::printf("  environment + light vs the sum of the two: ratio %.4f\n", a / b);
    EXPECT_NEAR(a / b, 1.0, 0.02);
}

// The same with an emissive quad instead of the punctual light, under a dim sky with a small bright sun
// (whose next-event samples carry nearly all its MIS weight): the environment and emissive strategies
// take their choice from the light sample's own first coordinate, rescaled to [0, 1) for the chosen one
// (shade.comp). Without the rescale each strategy would sample only part of its light and lose the
// rest of that light's next-event share.
TEST(PunctualLights, EnvironmentPlusEmissiveQuadIsTheSumOfBoth) {
    Scene s = lit_plane(PunctualLight{});
    s.lights.clear();
    Material lamp;
    lamp.emissive = glm::vec3(12.0f);
    lamp.base_color = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
    s.materials.push_back(lamp);
    Mesh quad = s.meshes[0]; // 10 m square (lit_plane scaled it); the instance shrinks it to 0.6 m
    quad.triangle_material.assign(quad.triangle_material.size(), 1u);
    s.meshes.push_back(quad);
    Instance li;
    li.mesh = 1;
    // 0.6 m square at z = 1.2 facing down (180 degrees about x), off the image centre.
    li.object_to_world = glm::mat4(0.06f, 0, 0, 0, 0, -0.06f, 0, 0, 0, 0, -1, 0, 0.3f, 0.2f, 1.2f, 1);
    s.instances.push_back(li);
    Environment sky;
    sky.width = 64;
    sky.height = 32;
    sky.rgb.assign(size_t(sky.width) * sky.height * 3, 0.05f);
    for (uint32_t y = 9; y < 12; ++y) // a 2x3-texel sun above the plane (+z, tilted towards +y)
        for (uint32_t x = 62; x < 64; ++x)
            for (int c = 0; c < 3; ++c) sky.rgb[(size_t(y) * sky.width + x) * 3 + size_t(c)] = 60.0f;
    const Rendered both = render(s, sky, 64, 3);
    Scene no_lamp = s; // the quad stays, black: it shades the plane from the sky in both renders
    no_lamp.materials[1].emissive = glm::vec3(0.0f);
    const Rendered env_only = render(no_lamp, sky, 64, 3);
    const Rendered lamp_only = render(s, Environment{}, 64, 3);
    double a = 0.0, b = 0.0, lamp_sum = 0.0;
    for (size_t i = 0; i < both.image.pixel_count(); ++i) {
        a += both.image.data[i * 4 + 1];
        b += env_only.image.data[i * 4 + 1] + lamp_only.image.data[i * 4 + 1];
        lamp_sum += lamp_only.image.data[i * 4 + 1];
    }
    std::printf("  environment + emissive quad vs the sum of the two: ratio %.4f (lamp %.1f %% of it)\n", a / b,
                100.0 * lamp_sum / b);
    EXPECT_GT(lamp_sum, 0.1 * b); // both lights matter
    EXPECT_LT(lamp_sum, 0.8 * b);
    EXPECT_NEAR(a / b, 1.0, 0.02);
}

} // namespace
} // namespace nbvh::render
