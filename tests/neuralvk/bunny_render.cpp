#include "tests/neuralvk/bunny_render.h"

#include "engine/bvh/scene_accel.h"
#include "engine/scene/camera.h"
#include "engine/scene/environment.h"

namespace nbvh::test {

using namespace nbvh::render;

Rendered render_bunny(const Fixture& f, bool hybrid, const Tweak& tweak) {
    vk::ContextOptions co;
    co.device = vk::DeviceChoice::cpu;
    co.validation = true;
    vk::Context ctx(co);
    const SceneAccel accel = build_scene_accel(f.scene);
    Camera cam = auto_frame(f.scene, 1.0f);
    cam.yfov *= 0.5f; // the bunny fills most of the frame, so FLIP means measure the asset, not the sky
    RenderOptions o;
    o.width = o.height = 64;
    o.spp = 4;
    o.max_depth = 3;
    o.seed = 7;
    o.neural.roughness = 0.6f;
    o.neural.metallic = 0.0f;
    o.neural.path = NeuralPath::scalar;
    o.neural.secondary_lod = SECONDARY_LOD_SAME;
    if (hybrid)
        o.neural.model = &f.model;
    else
        o.neural.classical = true;
    if (tweak) tweak(o);
    WavefrontRenderer r(ctx, f.scene, accel, default_sky(), cam, o);
    RenderResult res = r.render();
    return {convert_channels(res.image, 3), res.stats, ctx.validation_message_count()};
}

// Batched rounds, leaves per round and the per-ray leaf budget (of every ray: the secondary budget 0).
Tweak rounds(uint32_t batched, uint32_t leaves_per_round, uint32_t max_leaves) {
    return [=](RenderOptions& o) {
        o.neural.batched_rounds = batched;
        o.neural.leaves_per_round = leaves_per_round;
        o.neural.leaves_per_round_camera = leaves_per_round;
        o.neural.max_rounds = max_leaves;
        o.neural.max_rounds_secondary = 0;
    };
}
double image_mean(const Image& image) {
    double m = 0.0;
    for (float v : image.data) m += v;
    return image.data.empty() ? 0.0 : m / double(image.data.size());
}

} // namespace nbvh::test
