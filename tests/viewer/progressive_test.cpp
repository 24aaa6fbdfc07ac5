// WavefrontRenderer's progressive entry points (the viewer's render loop) on lavapipe:
// N calls of render_progressive(1) give the same film as render() at N spp, and set_camera restarts
// the accumulation with the new view (same image as a fresh renderer made with that camera).
#include <gtest/gtest.h>

#include <cmath>

#include "assets/default_scene.h"
#include "engine/bvh/scene_accel.h"
#include "engine/render/wavefront.h"
#include "engine/scene/camera.h"
#include "engine/scene/environment.h"
#include "engine/vk/context.h"

namespace nbvh {
namespace {

struct Fixture {
    Scene scene = assets::make_default_scene();
    SceneAccel accel = build_scene_accel(scene);
    Environment env = default_sky();
};

const Fixture& fixture() {
    static const Fixture f;
    return f;
}

vk::Context make_context() {
    vk::ContextOptions o;
    o.device = vk::DeviceChoice::cpu;
    o.validation = true;
    return vk::Context(o);
}

render::RenderOptions small_options(uint32_t spp) {
    render::RenderOptions o;
    o.width = 24;
    o.height = 16;
    o.spp = spp;
    o.max_depth = 3;
    return o;
}

double max_abs_diff(const Image& a, const Image& b) {
    EXPECT_EQ(a.data.size(), b.data.size());
    double m = 0.0;
    for (size_t i = 0; i < std::min(a.data.size(), b.data.size()); ++i)
        m = std::max(m, double(std::abs(a.data[i] - b.data[i])));
    return m;
}

TEST(Progressive, OneSampleAtATimeEqualsOneRender) {
    const Fixture& f = fixture();
    vk::Context ctx = make_context();
    ASSERT_TRUE(ctx.validation_enabled());
    const Camera cam = auto_frame(f.scene, 1.5f);
    render::WavefrontRenderer once(ctx, f.scene, f.accel, f.env, cam, small_options(4));
    const render::RenderResult ref = once.render();

    render::WavefrontRenderer prog(ctx, f.scene, f.accel, f.env, cam, small_options(1));
    render::RenderResult r;
    for (int i = 0; i < 4; ++i) r = prog.render_progressive(1);
    EXPECT_EQ(prog.accumulated_samples(), 4u);
    EXPECT_EQ(r.stats.spp, 4u);
    EXPECT_LT(max_abs_diff(r.image, ref.image), 1e-5);

    // Negative control: after 1 sample the running mean differs from the 4-sample mean.
    render::WavefrontRenderer one(ctx, f.scene, f.accel, f.env, cam, small_options(1));
    EXPECT_GT(max_abs_diff(one.render_progressive(1).image, ref.image), 1e-3);
    EXPECT_EQ(ctx.validation_message_count(), 0);
}

// A film left by render() goes on with render_progressive: the samples after it are the one-shot render's
// next ones (the study extends its floor render to the equal-time spp this way). 20 + 13 samples cross
// the multi-sample waves (up to 32 samples of a small image per wave) unaligned.
TEST(Progressive, RenderThenMoreSamplesEqualsOneLongerRender) {
    const Fixture& f = fixture();
    vk::Context ctx = make_context();
    const Camera cam = auto_frame(f.scene, 1.5f);
    render::WavefrontRenderer once(ctx, f.scene, f.accel, f.env, cam, small_options(33));
    const render::RenderResult ref = once.render();

    render::WavefrontRenderer film(ctx, f.scene, f.accel, f.env, cam, small_options(20));
    const render::RenderResult first = film.render();
    const render::RenderResult more = film.render_progressive(13);
    EXPECT_EQ(film.accumulated_samples(), 33u);
    EXPECT_EQ(more.stats.spp, 33u);
    EXPECT_LT(max_abs_diff(more.image, ref.image), 1e-5);
    EXPECT_GT(max_abs_diff(first.image, ref.image), 1e-4); // control: 20 samples are not 33
    EXPECT_EQ(ctx.validation_message_count(), 0);
}

TEST(Progressive, SetCameraRestartsWithTheNewView) {
    const Fixture& f = fixture();
    vk::Context ctx = make_context();
    const Camera a = auto_frame(f.scene, 1.5f);
    Camera b = a;
    b.eye = a.target + glm::vec3(-1.0f, 0.6f, 0.8f) * glm::length(a.eye - a.target);

    render::WavefrontRenderer fresh(ctx, f.scene, f.accel, f.env, b, small_options(2));
    const render::RenderResult ref = fresh.render();

    render::WavefrontRenderer prog(ctx, f.scene, f.accel, f.env, a, small_options(1));
    const render::RenderResult first = prog.render_progressive(2);
    prog.set_camera(b);
    EXPECT_EQ(prog.accumulated_samples(), 0u);
    const render::RenderResult moved = prog.render_progressive(2);
    EXPECT_LT(max_abs_diff(moved.image, ref.image), 1e-5);
    EXPECT_GT(max_abs_diff(first.image, ref.image), 1e-3); // the views differ (control)
    EXPECT_EQ(ctx.validation_message_count(), 0);
}

} // namespace
} // namespace nbvh
