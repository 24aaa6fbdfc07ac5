// What a viewer setting change costs, in frames (issue 13: "a slider change costs no more than two
// frames"), and the viewer's progressive frame against `nbvh render`'s (issue 13: "within 10 %").
// Not a test: a benchmark executable; numbers only mean something on a GPU (lavapipe times say
// nothing), measured in one run on one device. No window (the GPU machine has no display): the viewer's
// frame is the renderer's render_progressive(1, no read-back) plus the presenter's film stage recorded
// into one of FRAMES_IN_FLIGHT frame slots and submitted without waiting (app/viewer/film_stage.h, the
// presenter's own code), so swapchain, blit and UI are not counted. For comparison the same frame with
// a blocking wait for the film stage (the viewer before frames in flight). A change is timed from the
// settings call to the end of the first frame that shows it (its film stage done). Changes: the
// sliders (apply()), and a model swap (apply() with another model of the same assets: the model file
// loaded again, or --swap-model B.nbvh), each against a rebuild.
//
// Usage: nbvh_bench_viewer_latency SCENE|default MODEL.nbvh [--swap-model B.nbvh] [--width 1920
//        --height 1080] [--frames 32] [--device auto|gpu|cpu] [--json OUT.json]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/viewer/film_stage.h"
#include "assets/default_scene.h"
#include "engine/bvh/scene_accel.h"
#include "engine/core/error.h"
#include "engine/neural/asset_table.h"
#include "engine/neural/model_file.h"
#include "engine/render/wavefront.h"
#include "engine/scene/camera.h"
#include "engine/scene/environment.h"
#include "engine/scene/gltf_loader.h"
#include "engine/vk/commands.h"

using namespace nbvh;
using clock_type = std::chrono::steady_clock;

namespace {

double ms_since(clock_type::time_point t0) {
    return std::chrono::duration<double, std::milli>(clock_type::now() - t0).count();
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

struct Args {
    std::string scene, model, swap_model, device = "auto", json;
    uint32_t width = 1920, height = 1080, frames = 32;
};

Args parse(int argc, char** argv) {
    Args a;
    std::vector<std::string> pos;
    for (int i = 1; i < argc; ++i) {
        const std::string s = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) throw Error(s + ": missing value");
            return argv[++i];
        };
        if (s == "--width") a.width = uint32_t(std::stoul(next()));
        else if (s == "--height") a.height = uint32_t(std::stoul(next()));
        else if (s == "--frames") a.frames = std::max(4u, uint32_t(std::stoul(next())));
        else if (s == "--device") a.device = next();
        else if (s == "--json") a.json = next();
        else if (s == "--swap-model") a.swap_model = next();
        else pos.push_back(s);
    }
    if (pos.size() != 2) throw Error("usage: nbvh_bench_viewer_latency SCENE|default MODEL.nbvh [options]");
    a.scene = pos[0];
    a.model = pos[1];
    return a;
}

} // namespace

int main(int argc, char** argv) try {
    const Args a = parse(argc, argv);
    const NeuralModel model = load_model(a.model);
    const NeuralModel other = load_model(a.swap_model.empty() ? a.model : a.swap_model); // another object
    Scene scene = a.scene == "default" ? assets::make_default_scene() : load_gltf(a.scene, {});
    bind_model_to_scene(scene, model, a.model);
    const SceneAccel accel = build_scene_accel(scene);
    const Environment env = scene.environment.empty() ? default_sky() : scene.environment;
    const Camera camera = scene.has_camera ? scene.camera : auto_frame(scene, float(a.width) / float(a.height));
    vk::ContextOptions copt;
    copt.set_device(a.device); // auto, gpu, gpu:N or cpu, as the CLI
    vk::Context ctx(copt);

    render::RenderOptions o;
    o.width = a.width;
    o.height = a.height;
    o.spp = 1;
    o.max_depth = 8;
    o.neural.model = &model; // as the viewer: one renderer, settings and models through apply()
    render::WavefrontRenderer r(ctx, scene, accel, env, camera, o);
    // The presenter's frame slots (film stage + command buffer each), driven as the presenter does.
    std::vector<std::unique_ptr<viewer::FrameSlot>> slots;
    for (uint32_t i = 0; i < viewer::FRAMES_IN_FLIGHT; ++i)
        slots.push_back(std::make_unique<viewer::FrameSlot>(ctx, false, "bench frame"));
    uint64_t frame_no = 0;
    viewer::FilmSource film;
    film.width = a.width;
    film.height = a.height;
    // One viewer frame: one sample into the film, then the film stage into the next slot, not waited
    // for (frames in flight); `block` waits for it (the viewer before frames in flight).
    auto frame = [&](bool block) -> viewer::FrameSlot& {
        r.render_progressive(1, false);
        viewer::FrameSlot& f = *slots[frame_no++ % slots.size()];
        f.cmd.wait();
        f.cmd.begin();
        film.linear = &r.output();
        f.film.record(f.cmd, film);
        f.cmd.submit();
        if (block) f.cmd.wait();
        return f;
    };
    auto steady_frame_ms = [&](bool block) {
        for (int i = 0; i < 4; ++i) frame(block); // warm-up (pipelines, caches, clocks)
        std::vector<double> steady;
        for (uint32_t i = 0; i < a.frames; ++i) {
            const auto t0 = clock_type::now();
            frame(block);
            steady.push_back(ms_since(t0));
        }
        ctx.wait_idle();
        return median(steady);
    };
    const double blocking_ms = steady_frame_ms(true);
    const double frame_ms = steady_frame_ms(false);

    // Each change: apply() and the first frame of the new setting (what the user waits for), median of
    // several; the setting goes back and forth so every measurement is a real change.
    struct Change {
        const char* name;
        std::function<void(render::RenderOptions&, bool)> set;
    };
    const uint32_t lods = std::max(1u, model.lod_count);
    std::vector<Change> changes = {
        {"lod", [&](render::RenderOptions& x, bool b) { x.neural.lod = b ? lods - 1 : 0; }},
        {"secondary_lod", [&](render::RenderOptions& x, bool b) { x.neural.secondary_lod = b ? int32_t(lods - 1) : -1; }},
        {"neural_off", [](render::RenderOptions& x, bool b) { x.neural.classical = b; }},
        {"max_depth", [](render::RenderOptions& x, bool b) { x.max_depth = b ? 4 : 8; }},
        {"roughness_override", [](render::RenderOptions& x, bool b) { x.neural.roughness = b ? 0.3f : -1.0f; }},
    };
    changes.push_back({"model_swap", [&](render::RenderOptions& x, bool b) { x.neural.model = b ? &other : &model; }});
    nlohmann::json rows = nlohmann::json::array();
    std::printf("device        %s\n", ctx.features().device_name.c_str());
    std::printf("film          %ux%u, model %s (%u LoDs), swap model %s\n", a.width, a.height, a.model.c_str(), lods,
                a.swap_model.empty() ? "(the same file, loaded again)" : a.swap_model.c_str());
    std::printf("viewer frame  %.3f ms with %u frames in flight, %.3f ms blocking (median of %u: 1 spp + film stage)\n\n",
                frame_ms, viewer::FRAMES_IN_FLIGHT, blocking_ms, a.frames);
    std::printf("%-20s %12s %12s %8s\n", "change", "apply ms", "to frame ms", "frames");
    for (const Change& c : changes) {
        std::vector<double> apply_ms, total_ms;
        for (uint32_t i = 0; i < 8; ++i) {
            render::RenderOptions x = o;
            c.set(x, i % 2 == 0);
            ctx.wait_idle(); // from a quiet queue: the change's own cost
            const auto t0 = clock_type::now();
            if (!r.apply(x)) throw Error(std::string("apply refused the change ") + c.name);
            apply_ms.push_back(ms_since(t0));
            frame(false).cmd.wait(); // the first frame showing the change, done
            total_ms.push_back(ms_since(t0));
        }
        const double t = median(total_ms);
        std::printf("%-20s %12.3f %12.3f %8.2f\n", c.name, median(apply_ms), t, t / frame_ms);
        rows.push_back({{"change", c.name}, {"apply_ms", median(apply_ms)}, {"to_first_frame_ms", t},
                        {"frames", t / frame_ms}});
        ctx.wait_idle();
        r.apply(o);
    }
    if (r.model_swaps() == 0) throw Error("no model swap happened");
    // For scale: what a rebuild (a new renderer: scene upload, pipelines) costs.
    const auto t0 = clock_type::now();
    {
        render::WavefrontRenderer fresh(ctx, scene, accel, env, camera, o);
        fresh.render_progressive(1, false);
    }
    const double rebuild_ms = ms_since(t0);
    std::printf("%-20s %12s %12.3f %8.2f\n", "(rebuild)", "-", rebuild_ms, rebuild_ms / frame_ms);

    // nbvh render's frame: render() at N spp in one call, per sample, against the viewer's frame.
    render::RenderOptions ro = o;
    ro.spp = a.frames;
    render::WavefrontRenderer once(ctx, scene, accel, env, camera, ro);
    once.render(); // warm-up
    const auto t1 = clock_type::now();
    const render::RenderResult rr = once.render();
    const double render_ms = ms_since(t1) / double(a.frames);
    std::printf("\nnbvh render   %.3f ms per sample (%u spp in one call, read-back included); viewer/render %.3f\n",
                render_ms, a.frames, frame_ms / render_ms);
    if (!a.json.empty()) {
        nlohmann::json j = {{"device", ctx.features().device_name}, {"width", a.width}, {"height", a.height},
                            {"model", a.model}, {"scene", a.scene}, {"viewer_frame_ms", frame_ms},
                            {"render_ms_per_sample", render_ms}, {"render_gpu_ms_per_sample", rr.stats.gpu_ms / a.frames},
                            {"viewer_over_render", frame_ms / render_ms}, {"rebuild_ms", rebuild_ms}, {"changes", rows},
                            {"viewer_frame_blocking_ms", blocking_ms}, {"frames_in_flight", viewer::FRAMES_IN_FLIGHT},
                            {"swap_model", a.swap_model.empty() ? a.model : a.swap_model}};
        std::ofstream(a.json) << j.dump(2) << "\n";
    }
    return 0;
} catch (const Error& e) {
    std::fprintf(stderr, "nbvh_bench_viewer_latency: error: %s\n", e.what());
    return 1;
}
