// A scene scaled by `scale` about the origin and then moved by `offset` (tests of issue 12 "Any scale,
// anywhere"): every instance transform, the punctual lights (positions and ranges; point and spot
// intensities x scale^2, so that the irradiance at the scaled distances stays the same) and a glTF camera.
// Radiance-based inputs (emissive triangles, environment) do not depend on scale, so a renderer free of
// scale-dependent constants renders the same image. expect_every_scale_matches() is the check both the
// classical and the hybrid scale tests run.
#pragma once
#include <gtest/gtest.h>

#include <cstdio>
#include <functional>
#include <span>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/core/exposure.h"
#include "engine/core/flip.h"
#include "engine/core/image.h"
#include "engine/bvh/scene_accel.h"
#include "engine/render/wavefront.h"
#include "engine/scene/camera.h"
#include "engine/scene/scene.h"
#include "engine/vk/context.h"

namespace nbvh::test {

inline Scene scaled_scene(Scene s, float scale, const glm::vec3& offset) {
    const glm::mat4 m = glm::translate(glm::mat4(1.0f), offset) * glm::scale(glm::mat4(1.0f), glm::vec3(scale));
    for (Instance& inst : s.instances) inst.object_to_world = m * inst.object_to_world;
    for (PunctualLight& l : s.lights) {
        l.position = glm::vec3(m * glm::vec4(l.position, 1.0f));
        l.range *= scale;
        if (l.type != LightType::directional) l.intensity *= scale * scale;
    }
    s.camera.eye = glm::vec3(m * glm::vec4(s.camera.eye, 1.0f));
    s.camera.target = glm::vec3(m * glm::vec4(s.camera.target, 1.0f));
    return s;
}

struct ScaledRender {
    Image image;
    render::RenderStats stats;
    int validation = 0; // validation-layer messages of the render's context
};

// A 64x48 render of `scene` on lavapipe with the validation layer, framed by the automatic camera (which
// frames every scale alike); `o` gives spp, depth, seed and the neural settings.
inline ScaledRender render_scaled(const Scene& scene, const Environment& env, render::RenderOptions o) {
    vk::ContextOptions co;
    co.device = vk::DeviceChoice::cpu;
    co.validation = true;
    vk::Context ctx(co);
    const SceneAccel accel = build_scene_accel(scene);
    o.width = 64;
    o.height = 48;
    render::WavefrontRenderer r(ctx, scene, accel, env, auto_frame(scene, 64.0f / 48.0f), o);
    render::RenderResult res = r.render();
    return {std::move(res.image), res.stats, ctx.validation_message_count()};
}

struct ScaleCase {
    const char* name;
    float scale;
    glm::vec3 offset;
};

// Renders `base` at `seed` (the reference) and `seed + 1` (the noise floor: LDR-FLIP of the two at the
// reference's auto exposure), then every case scaled at `seed`: no validation message, no non-finite
// pixel or sample, LDR-FLIP against the reference at most `fraction_of_floor` x the floor. `check` adds
// the caller's checks of each case against the reference.
inline void expect_every_scale_matches(
    const Scene& base, std::span<const ScaleCase> cases, uint32_t seed, double fraction_of_floor,
    const std::function<ScaledRender(const Scene&, uint32_t)>& render,
    const std::function<void(const ScaledRender& ref, const ScaledRender& r)>& check = {}) {
    const ScaledRender ref = render(base, seed);
    EXPECT_EQ(ref.validation, 0);
    const float stops = auto_exposure(ref.image).stops;
    const Image ref_px = as_png_pixels(ref.image, stops);
    const double floor = flip_ldr(ref_px, as_png_pixels(render(base, seed + 1).image, stops)).mean;
    std::printf("noise floor (1 m, other seed): %.4f\n", floor);
    ASSERT_GT(floor, 0.01) << "a floor of nothing would make the bound meaningless";
    for (const ScaleCase& c : cases) {
        SCOPED_TRACE(c.name);
        const ScaledRender r = render(scaled_scene(base, c.scale, c.offset), seed);
        EXPECT_EQ(r.validation, 0);
        EXPECT_EQ(r.stats.nonfinite_pixels, 0u);
        EXPECT_EQ(r.stats.nonfinite_samples, 0u);
        const double flip = flip_ldr(ref_px, as_png_pixels(r.image, stops)).mean;
        std::printf("%-32s FLIP vs 1 m %.4f (bound %.4f)\n", c.name, flip, fraction_of_floor * floor);
        EXPECT_LE(flip, fraction_of_floor * floor);
        if (check) check(ref, r);
    }
}

} // namespace nbvh::test
