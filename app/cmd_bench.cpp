// nbvh bench SCENE --model M.nbvh [--width --height --spp --max-depth --seed] [--device auto|gpu|cpu]
//                  [--repeat R] [--json FILE.json] [--neural-path auto|scalar|coopmat] [--camera] [--env]
// What accuracy costs in time: in one process on one device, renders the classical reference (neural
// instances from their triangles, neural material constants: `nbvh render --classical`) and the hybrid
// image at every level of detail of the model, each timed with GPU timestamps (median of R renders after
// one warm-up), and scores each hybrid image with LDR-FLIP against the reference. Both images are
// compared as `nbvh render` writes PNGs (ACES tone map, 8-bit sRGB), i.e. as `nbvh flip a.png b.png`.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/output_path.h"
#include "app/render_args.h"
#include "app/scene_arg.h"
#include "engine/bvh/scene_accel.h"
#include "engine/core/error.h"
#include "engine/core/flip.h"
#include "engine/core/image.h"
#include "engine/core/log.h"
#include "engine/neural/model_file.h"
#include "engine/render/wavefront.h"
#include "engine/vk/context.h"
#include "shaders/shared/bvh_node.h"

namespace nbvh::app {
namespace {

struct BenchArgs {
    std::string scene, model, device = "auto", json, neural_path = "auto", camera, env;
    std::optional<float> env_rotation; // degrees
    uint32_t repeat = 3;
    render::RenderOptions options;
    BenchArgs() {
        options.width = 1920;
        options.height = 1080;
        options.spp = 1;
    }
};

struct Timed {
    render::RenderStats stats; // of the median run (by GPU time)
    Image image;               // of the last run
};

// One warm-up render (pipelines, caches, clocks), then `repeat` timed ones; the median by GPU time.
Timed time_renders(const vk::Context& ctx, const Scene& scene, const SceneAccel& accel, const Environment& env,
                   const Camera& camera, const render::RenderOptions& options, uint32_t repeat) {
    render::WavefrontRenderer renderer(ctx, scene, accel, env, camera, options);
    renderer.render();
    std::vector<render::RenderStats> runs;
    Timed t;
    for (uint32_t i = 0; i < repeat; ++i) {
        render::RenderResult r = renderer.render();
        runs.push_back(std::move(r.stats));
        if (i + 1 == repeat) t.image = std::move(r.image);
    }
    std::sort(runs.begin(), runs.end(), [](const auto& a, const auto& b) { return a.gpu_ms < b.gpu_ms; });
    t.stats = runs[runs.size() / 2];
    return t;
}

// The image as `nbvh render` writes it to PNG, decoded back to linear [0,1] (what flip_ldr expects).
Image as_png_pixels(const Image& linear) {
    PngEncode enc;
    enc.tone_map = ToneMap::aces;
    int channels = 0;
    const std::vector<uint8_t> px = to_srgb8(linear, enc, &channels);
    Image out(linear.width, linear.height, 3);
    for (size_t i = 0; i < linear.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) out.data[i * 3 + c] = srgb_to_linear(float(px[i * size_t(channels) + c]) / 255.0f);
    return out;
}

// GPU bytes of the model rendered at LoD `lod`: the cut's interior nodes instead of LoD 0's.
uint64_t lod_gpu_bytes(const NeuralModel& m, uint32_t lod) {
    const uint64_t all = model_gpu_bytes(m);
    if (lod >= m.lod_node_counts.size()) return all;
    const uint64_t in0 = m.lod_node_counts[0] / 2 + 1, in_l = m.lod_node_counts[lod] / 2 + 1;
    return all - in0 * sizeof(GpuBvhNode) + in_l * sizeof(GpuBvhNode);
}

void run_bench(const BenchArgs& a) {
    check_output_path(a.json, "--json", {a.scene, a.model, a.env});
    vk::ContextOptions copt;
    copt.device = vk::parse_device_choice(a.device);
    render::RenderOptions options = a.options;
    options.neural.path = render::parse_neural_path(a.neural_path);
    if (a.repeat == 0) throw Error("--repeat must be at least 1");
    const NeuralModel model = load_model(a.model);
    const Scene scene = load_scene_for_model(a.scene, {}, &model, a.model);
    Environment env = choose_environment(scene, a.env);
    if (a.env_rotation) env.rotation = *a.env_rotation * 3.14159265358979f / 180.0f;
    const Camera camera = choose_camera(scene, a.camera, options);
    vk::Context ctx(copt);
    const SceneAccel accel = build_scene_accel(scene);

    render::RenderOptions ref_opt = options;
    ref_opt.neural.classical = true;
    render::validate(ref_opt.neural, scene);
    const Timed ref = time_renders(ctx, scene, accel, env, camera, ref_opt, a.repeat);
    const Image ref_px = as_png_pixels(ref.image);
    const double ref_ms = ref.stats.gpu_ms;

    std::printf("device      %s (driver %s)\n", ref.stats.device.c_str(), ref.stats.driver.c_str());
    std::printf("scene       %s, %ux%u, %u spp, max depth %u; median of %u after 1 warm-up\n", a.scene.c_str(),
                options.width, options.height, options.spp, options.max_depth, a.repeat);
    std::printf("FLIP        LDR-FLIP vs the classical reference, both ACES tone-mapped to 8-bit sRGB (as PNGs)\n");
    std::printf("classical   %.3f ms/frame GPU\n\n", ref_ms);
    std::printf("%4s %8s %10s %12s %9s %12s %12s %8s\n", "LoD", "nodes", "memory MB", "GPU ms/frame",
                "x classic", "queries/ray", "queries/s", "FLIP");

    nlohmann::json rows = nlohmann::json::array();
    std::string path_name;
    const uint32_t lods = std::max(1u, model.lod_count);
    for (uint32_t lod = 0; lod < lods; ++lod) {
        render::RenderOptions o = options;
        o.neural.model = &model;
        o.neural.lod = lod;
        o.neural.secondary_lod = -1;
        render::validate(o.neural, scene);
        const Timed t = time_renders(ctx, scene, accel, env, camera, o, a.repeat);
        const float flip = flip_ldr(ref_px, as_png_pixels(t.image)).mean;
        const render::RenderStats& s = t.stats;
        path_name = s.neural_path;
        const uint32_t nodes = lod < model.lod_node_counts.size() ? model.lod_node_counts[lod] : 0;
        const uint64_t bytes = lod_gpu_bytes(model, lod);
        const double ratio = ref_ms > 0.0 ? s.gpu_ms / ref_ms : 0.0;
        std::printf("%4u %8u %10.3f %12.3f %9.2f %12.2f %12.3g %8.4f\n", lod, nodes, double(bytes) / 1.0e6, s.gpu_ms,
                    ratio, s.neural_queries_per_ray(), s.neural_queries_per_second(), flip);
        nlohmann::json passes = nlohmann::json::object();
        for (const auto& [name, ms] : s.pass_ms) passes[name] = ms;
        rows.push_back({{"lod", lod}, {"nodes", nodes}, {"neural_bytes", bytes}, {"gpu_ms", s.gpu_ms},
                        {"wall_ms", s.wall_ms}, {"ratio_to_classical", ratio}, {"neural_queries", s.neural_queries},
                        {"queries_per_ray", s.neural_queries_per_ray()},
                        {"queries_per_second", s.neural_queries_per_second()}, {"query_gpu_ms", s.neural_query_ms},
                        {"pass_gpu_ms", passes}, {"flip", flip}});
    }
    std::printf("\nneural path %s\n", path_name.c_str());
    if (ctx.validation_enabled() && ctx.validation_message_count() > 0)
        log_warn("bench: %d Vulkan validation messages", ctx.validation_message_count());
    if (a.json.empty()) return;
    nlohmann::json ref_passes = nlohmann::json::object();
    for (const auto& [name, ms] : ref.stats.pass_ms) ref_passes[name] = ms;
    nlohmann::json j = {{"scene", a.scene}, {"model", a.model}, {"assets", model.assets.size()},
                        {"device", ref.stats.device}, {"driver", ref.stats.driver}, {"width", options.width},
                        {"height", options.height}, {"spp", options.spp}, {"max_depth", options.max_depth},
                        {"repeat", a.repeat}, {"neural_path", path_name},
                        {"flip_metric", "ldr: ACES tone map + 8-bit sRGB (as nbvh render PNGs), ppd 67.02"},
                        {"classical", {{"gpu_ms", ref_ms}, {"wall_ms", ref.stats.wall_ms}, {"pass_gpu_ms", ref_passes}}},
                        {"lods", rows}};
    write_text_atomically(a.json, j.dump(2) + "\n");
}

} // namespace

void add_bench_command(CLI::App& app) {
    auto args = std::make_shared<BenchArgs>();
    auto* cmd = app.add_subcommand("bench", "time the classical reference and every N-BVH level of detail; FLIP of each");
    cmd->add_option("scene", args->scene, "glTF/GLB file, or 'default' for the built-in scene")->required();
    cmd->add_option("--model", args->model, "N-BVH model (.nbvh) of the scene's neural asset")->required();
    add_render_option_flags(cmd, args->options);
    cmd->add_option("--device", args->device, "Vulkan device: auto, gpu or cpu (lavapipe)");
    cmd->add_option("--repeat", args->repeat, "timed renders per configuration (the median is reported)")
        ->check(CLI::Range(1u, 1000u));
    cmd->add_option("--json", args->json, "write the table (and per-pass GPU times) as JSON");
    cmd->add_option("--neural-path", args->neural_path, "MLP implementation: auto, scalar or coopmat");
    cmd->add_option("--camera", args->camera, "eye_x,eye_y,eye_z,target_x,target_y,target_z,fov_deg");
    cmd->add_option("--env", args->env, "environment map (.hdr or .exr, equirectangular), or 'none' (the scene's lights only)");
    cmd->add_option("--env-rotation", args->env_rotation, "rotate the environment about +y by this many degrees")
        ->check(CLI::Range(-3600.0f, 3600.0f));
    cmd->callback([args] { run_bench(*args); });
}

} // namespace nbvh::app
