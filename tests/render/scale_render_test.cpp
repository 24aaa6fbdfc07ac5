// Any scale, anywhere (issue 12), classical renders end to end on lavapipe (validation on): the default
// scene (16 m ground, textured checker, emissive lamp, chrome sphere, 384k-triangle rope knot, default
// sky) scaled by 6.25e-6 (0.1 mm), 1e-4 (1.6 mm) and 1e4 (160 km) about the origin, and at 1e4 moved
// 3000 km away (1e-4 is not moved: 3000 km away a float's spacing, 0.25 m, exceeds the whole 1.6 mm scene), framed by
// the automatic camera, rendered like the 1 m scene (same seed, spp, exposure). Each render has no
// non-finite pixel or sample and matches the 1 m render.
//
// Bound: LDR-FLIP (at the 1 m image's auto exposure) below a tenth of the noise floor (the 1 m scene with
// another seed vs the 1 m render; measured <= 0.001). Why: the scaled scenes are the 1 m scene up to float rounding of
// positions and of the camera, and share its random numbers, so nearly every path takes the same
// bounces (only paths that a rounding difference turns at a grazing edge, a Russian-roulette threshold
// or a lobe choice diverge: a few pixels). Precision artefacts are not small: self-intersection after an
// offset too small for the scale (shadow acne) darkens every lit surface, an offset too large for it
// (light leaking through contact points, peter-panning) or a camera framed at the wrong distance change
// most pixels, each a FLIP of the order of the noise floor or more (measured: see the test output).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "assets/default_scene.h"
#include "engine/bvh/scene_accel.h"
#include "engine/core/exposure.h"
#include "engine/core/flip.h"
#include "engine/core/image.h"
#include "engine/render/wavefront.h"
#include "engine/scene/camera.h"
#include "engine/vk/context.h"
#include "tests/render/scaled_scene.h"

namespace nbvh::render {
namespace {

constexpr double FRACTION_OF_FLOOR = 0.1;

struct Rendered {
    Image image;
    RenderStats stats;
    int validation = 0;
};

Rendered render(const Scene& scene, uint32_t seed) {
    vk::ContextOptions co;
    co.device = vk::DeviceChoice::cpu;
    co.validation = true;
    vk::Context ctx(co);
    const SceneAccel accel = build_scene_accel(scene);
    RenderOptions o;
    o.width = 64;
    o.height = 48;
    o.spp = 4;
    o.max_depth = 4;
    o.seed = seed;
    WavefrontRenderer r(ctx, scene, accel, scene.environment, auto_frame(scene, 64.0f / 48.0f), o);
    RenderResult res = r.render();
    return {std::move(res.image), res.stats, ctx.validation_message_count()};
}

// As an `nbvh render` PNG at a shared exposure, decoded to linear [0,1] RGB (what flip_ldr compares).
Image display(const Image& linear, float stops) {
    PngEncode enc;
    enc.tone_map = ToneMap::aces;
    enc.exposure = stops;
    int channels = 0;
    const std::vector<uint8_t> px = to_srgb8(linear, enc, &channels);
    Image out(linear.width, linear.height, 3);
    for (size_t i = 0; i < linear.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) out.data[i * 3 + c] = srgb_to_linear(float(px[i * size_t(channels) + c]) / 255.0f);
    return out;
}

Scene default_scene_auto_camera() {
    Scene s = assets::make_default_scene();
    s.has_camera = false; // the automatic camera frames every scale
    return s;
}

TEST(ScaleRender, DefaultSceneAtEveryScaleMatchesOneMetre) {
    const Scene base = default_scene_auto_camera();
    const Rendered ref = render(base, 5);
    const Rendered other = render(base, 6);
    const float stops = auto_exposure(ref.image).stops;
    const Image ref_px = display(ref.image, stops);
    const double floor = flip_ldr(ref_px, display(other.image, stops)).mean;
    std::printf("noise floor (1 m, other seed): %.4f\n", floor);
    ASSERT_GT(floor, 0.01) << "a floor of nothing would make the bound meaningless";
    struct Case {
        const char* name;
        float scale;
        glm::vec3 offset;
    };
    const Case cases[] = {{"6.25e-6 (0.1 mm) at the origin", 6.25e-6f, glm::vec3(0.0f)},
                          {"1e-4 (1.6 mm) at the origin", 1.0e-4f, glm::vec3(0.0f)},
                          {"1e4 (160 km) at the origin", 1.0e4f, glm::vec3(0.0f)},
                          {"1e4 (160 km), 3000 km away", 1.0e4f, glm::vec3(2.0e6f, 0.0f, -2.2e6f)}};
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        const Rendered r = render(test::scaled_scene(base, c.scale, c.offset), 5);
        EXPECT_EQ(r.validation, 0);
        EXPECT_EQ(r.stats.nonfinite_pixels, 0u);
        EXPECT_EQ(r.stats.nonfinite_samples, 0u);
        const double flip = flip_ldr(ref_px, display(r.image, stops)).mean;
        std::printf("%-32s FLIP vs 1 m %.4f (bound %.4f)\n", c.name, flip, FRACTION_OF_FLOOR * floor);
        EXPECT_LE(flip, FRACTION_OF_FLOOR * floor);
    }
}

} // namespace
} // namespace nbvh::render
