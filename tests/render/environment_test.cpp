// The environment map on lavapipe: radiance is read bilinearly (a sky seen directly has no texel steps)
// while directions are drawn piecewise-constant from the texels' filtered densities
// (engine/render/environment_sampler.cpp, shaders/lib/env.glsl). The second test integrates a plane's
// reflected radiance under a strongly non-uniform map on the CPU and checks the path tracer's NEE + MIS
// estimate against it: a pdf that disagreed with the sampling procedure would bias it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/render/wavefront.h"
#include "engine/scene/environment.h"
#include "shaders/shared/sampling.h"
#include "tests/render/test_scenes.h"

namespace nbvh::render {
namespace {

RenderResult render_env(const Scene& scene, const Environment& env, uint32_t spp, uint32_t max_depth, uint32_t size,
                        int& validation) {
    RenderOptions opt;
    opt.width = size;
    opt.height = size;
    opt.spp = spp;
    opt.max_depth = max_depth;
    opt.seed = 5;
    test::LavapipeRender r = test::render_lavapipe(scene, env, scene.camera, opt);
    validation = r.validation_enabled ? r.validation : -1;
    return std::move(r.result);
}

// The shader's lookup (lib/env.glsl nb_env_bilinear) on the CPU, through the same footprint.
float bilinear(const Environment& env, glm::vec2 uv, int c) {
    uvec2 lo, hi;
    vec2 f;
    nb_env_bilinear_footprint(uv, env.width, env.height, lo, hi, f);
    auto t = [&](uint32_t x, uint32_t y) { return env.rgb[(size_t(y) * env.width + x) * 3 + c]; };
    const float top = t(lo.x, lo.y) * (1.0f - f.x) + t(hi.x, lo.y) * f.x;
    const float bottom = t(lo.x, hi.y) * (1.0f - f.x) + t(hi.x, hi.y) * f.x;
    return top * (1.0f - f.y) + bottom * f.y;
}

// A camera at the origin looking down -z sees the sky around u = 0.5, the left edge of texel column 2 of a
// 4-column map whose column 2 alone is bright: nearest-texel lookups give each pixel 0 or 1 (the image
// splits in half), the bilinear lookup ~0.5 everywhere in this narrow view, rising to the right.
TEST(EnvironmentLookup, SkySeenDirectlyIsBilinear) {
    Scene s = test::make_quad_scene();
    s.instances[0].object_to_world = glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.0f, 50.0f)); // behind
    s.camera.eye = {0, 0, 0};
    s.camera.target = {0, 0, -1};
    s.camera.yfov = 0.05f;
    Environment env;
    env.width = 4;
    env.height = 2;
    env.rgb.assign(4 * 2 * 3, 0.0f);
    for (int y = 0; y < 2; ++y)
        for (int c = 0; c < 3; ++c) env.rgb[(size_t(y) * 4 + 2) * 3 + c] = 1.0f;
    int validation = -1;
    const RenderResult r = render_env(s, env, 16, 1, 8, validation);
    EXPECT_EQ(validation, 0);
    const Image& img = r.image;
    for (uint32_t y = 0; y < 8; ++y) {
        float prev = -1.0f;
        for (uint32_t x = 0; x < 8; ++x) {
            const float v = img.data[(size_t(y) * 8 + x) * 4 + 1];
            EXPECT_GT(v, 0.45f) << "pixel " << x << "," << y;
            EXPECT_LT(v, 0.55f) << "pixel " << x << "," << y;
            EXPECT_GT(v, prev) << "pixel " << x << "," << y << ": u grows to the right";
            prev = v;
        }
    }
}

// A rough plane facing the camera under a 16x8 map with a bright 2x2 patch (a "window" at 25x the rest)
// reflects the integral of the map over its hemisphere. The reference integrates the same bilinear
// radiance with the same BSDF (shared/sampling.h GGX + Lambert, as lib/material.glsl) on a fine grid.
TEST(EnvironmentLookup, PlaneUnderAMapMatchesItsIntegral) {
    Scene s = test::make_quad_scene();
    s.materials[0].roughness = 1.0f;
    s.materials[0].base_color = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
    s.camera.yfov = 0.02f; // every pixel sees the quad at its centre, normal +z, wo = +z
    Environment env;
    env.width = 16;
    env.height = 8;
    env.rgb.assign(16 * 8 * 3, 0.2f);
    // The plane's normal +z is u = 0 (= 1): the patch takes columns 15 and 0, across the seam (u wraps),
    // rows 2-3 (0 to 45 degrees above the horizon).
    for (int y = 2; y <= 3; ++y)
        for (int x : {0, 15})
            for (int c = 0; c < 3; ++c) env.rgb[(size_t(y) * 16 + x) * 3 + c] = 5.0f;
    int validation = -1;
    const RenderResult r = render_env(s, env, 512, 2, 4, validation);
    EXPECT_EQ(validation, 0);
    double rendered = 0.0;
    for (size_t i = 0; i < r.image.pixel_count(); ++i) rendered += r.image.data[i * 4 + 1];
    rendered /= double(r.image.pixel_count());

    // Reference: integral over the hemisphere around +z of L(w) f(wo, w) cos, wo = +z, in (phi, cos theta).
    const float alpha = nb_ggx_alpha(1.0f);
    const vec3 f0(0.04f);
    const int nphi = 1024, nmu = 512;
    double sum = 0.0;
    for (int i = 0; i < nmu; ++i) {
        const double mu = (i + 0.5) / nmu; // cos theta about +z
        const double st = std::sqrt(std::max(0.0, 1.0 - mu * mu));
        for (int j = 0; j < nphi; ++j) {
            const double phi = 2.0 * NB_PI * (j + 0.5) / nphi;
            const glm::vec3 wi(float(st * std::cos(phi)), float(st * std::sin(phi)), float(mu));
            const glm::vec3 h = glm::normalize(wi + glm::vec3(0, 0, 1));
            const float n_dot_h = h.z, v_dot_h = glm::dot(glm::vec3(0, 0, 1), h);
            const vec3 F = nb_fresnel_schlick(f0, v_dot_h);
            const float spec = F.y * nb_ggx_d(n_dot_h, alpha) * nb_ggx_v(float(mu), 1.0f, alpha);
            const float diff = 0.8f * NB_INV_PI;
            const float L = bilinear(env, nb_env_dir_to_uv(vec3(wi.x, wi.y, wi.z), 0.0f), 1);
            sum += double(L) * double(spec + diff) * mu;
        }
    }
    const double reference = sum * (2.0 * NB_PI / nphi) * (1.0 / nmu);
    EXPECT_NEAR(rendered, reference, 0.02 * reference) << "rendered " << rendered << ", integral " << reference;
}

} // namespace
} // namespace nbvh::render
