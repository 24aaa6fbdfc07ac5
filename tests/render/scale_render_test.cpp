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

#include "assets/default_scene.h"
#include "engine/render/wavefront.h"
#include "tests/render/scaled_scene.h"

namespace nbvh::render {
namespace {

constexpr double FRACTION_OF_FLOOR = 0.1;

using test::ScaledRender;

ScaledRender render(const Scene& scene, uint32_t seed) {
    RenderOptions o;
    o.spp = 4;
    o.max_depth = 4;
    o.seed = seed;
    return test::render_scaled(scene, scene.environment, o);
}

Scene default_scene_auto_camera() {
    Scene s = assets::make_default_scene();
    s.has_camera = false; // the automatic camera frames every scale
    return s;
}

TEST(ScaleRender, DefaultSceneAtEveryScaleMatchesOneMetre) {
    const test::ScaleCase cases[] = {{"6.25e-6 (0.1 mm) at the origin", 6.25e-6f, glm::vec3(0.0f)},
                                     {"1e-4 (1.6 mm) at the origin", 1.0e-4f, glm::vec3(0.0f)},
                                     {"1e4 (160 km) at the origin", 1.0e4f, glm::vec3(0.0f)},
                                     {"1e4 (160 km), 3000 km away", 1.0e4f, glm::vec3(2.0e6f, 0.0f, -2.2e6f)}};
    test::expect_every_scale_matches(default_scene_auto_camera(), cases, 5, FRACTION_OF_FLOOR, render);
}

} // namespace
} // namespace nbvh::render
