// nbvh bench SCENE --model M.nbvh [--width --height --spp --max-depth --seed] [--device auto|gpu|cpu]
//                  [--repeat R] [--json FILE.json] [--neural-path auto|scalar|coopmat] [--camera] [--env]
// What accuracy costs in time, quickly: in one process on one device, renders the classical reference
// (the true scene) and the hybrid image at every level of detail of the model, each timed with GPU
// timestamps (median of R renders after one warm-up), and scores each hybrid image with LDR-FLIP against
// the reference (both as `nbvh render` writes PNGs: ACES tone map, 8-bit sRGB). The hybrid renders share
// the reference's random numbers (same seed and spp), so their FLIP is mostly the neural error; beside it
// the noise floor (the classical render with another seed vs the reference) says how much of a FLIP
// noise alone gives at this spp. Converged figures over cameras and configurations: `nbvh study`.
// Any scene works: the model's asset table decides which instances are neural.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/build_info.h"
#include "app/output_path.h"
#include "app/render_args.h"
#include "app/render_measure.h"
#include "engine/bvh/scene_accel.h"
#include "engine/core/error.h"
#include "engine/core/flip.h"
#include "engine/core/image.h"
#include "engine/core/log.h"
#include "engine/neural/model_file.h"
#include "engine/render/gpu_memory.h"
#include "engine/render/wavefront.h"
#include "engine/vk/context.h"

namespace nbvh::app {
namespace {

struct BenchArgs {
    std::string scene, model, device = "auto", json, neural_path = "auto", camera, env, command_line;
    std::optional<float> env_rotation; // degrees
    uint32_t repeat = 3;
    uint32_t subdivide = 0; // --subdivide (engine/scene/subdivide.h)
    render::RenderOptions options;
    BenchArgs() {
        options.width = 1920;
        options.height = 1080;
        options.spp = 4; // the frame figures of results/ are 4 spp
    }
};

struct Timed {
    render::RenderStats stats; // of the median run (by GPU time)
    Image image;               // of the last run
};

// One warm-up render, then `repeat` timed ones (render_measure.h); the last image.
Timed time_renders(const vk::Context& ctx, const Scene& scene, const SceneAccel& accel, const Environment& env,
                   const Camera& camera, const render::RenderOptions& options, uint32_t repeat) {
    render::WavefrontRenderer renderer(ctx, scene, accel, env, camera, options);
    Timed t;
    t.stats = median_render_stats(renderer, repeat);
    t.image = renderer.render().image;
    return t;
}

void run_bench(const BenchArgs& a) {
    check_output_path(a.json, "--json", {a.scene, a.model, a.env});
    vk::ContextOptions copt;
    copt.set_device(a.device);
    render::RenderOptions options = a.options;
    options.neural.path = render::parse_neural_path(a.neural_path);
    if (a.repeat == 0) throw Error("--repeat must be at least 1");
    const ModelScene ms =
        load_model_scene(a.scene, a.model, a.env, a.env_rotation, a.camera, options, a.subdivide);
    const NeuralModel& model = ms.model;
    const Scene& scene = ms.scene;
    const Environment& env = ms.env;
    const Camera& camera = ms.camera;
    vk::Context ctx(copt);
    const SceneAccel accel = build_scene_accel(scene);

    render::RenderOptions ref_opt = options;
    ref_opt.neural.classical = true;
    render::validate(ref_opt.neural, scene);
    const Timed ref = time_renders(ctx, scene, accel, env, camera, ref_opt, a.repeat);
    const Image ref_px = as_png_pixels(ref.image);
    const double ref_ms = ref.stats.gpu_ms;
    // The noise floor: the same classical render with other random numbers.
    render::RenderOptions floor_opt = ref_opt;
    floor_opt.seed = ref_opt.seed + 1;
    const double floor = [&] {
        render::WavefrontRenderer r(ctx, scene, accel, env, camera, floor_opt);
        return double(flip_ldr(ref_px, as_png_pixels(r.render().image)).mean);
    }();
    const render::NeuralGpuBytes mem = render::neural_gpu_bytes(model);

    std::printf("device      %s (driver %s)\n", ref.stats.device.c_str(), ref.stats.driver.c_str());
    std::printf("scene       %s, %ux%u, %u spp, max depth %u; median of %u after 1 warm-up\n", a.scene.c_str(),
                options.width, options.height, options.spp, options.max_depth, a.repeat);
    std::printf("FLIP        LDR-FLIP vs the classical reference (same seed and spp: shared random numbers), both "
                "ACES tone-mapped to 8-bit sRGB (as PNGs)\n");
    std::printf("noise floor %.4f (the classical render with another seed vs the reference; rows marked * are within "
                "2x of it: not distinguishable from noise at %u spp; converged figures: nbvh study)\n",
                floor, options.spp);
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
        const uint64_t bytes = mem.total_for_lod(lod);
        const double ratio = ref_ms > 0.0 ? s.gpu_ms / ref_ms : 0.0;
        const bool noise = flip <= 2.0 * floor;
        std::printf("%4u %8u %10.3f %12.3f %9.2f %12.2f %12.3g %8.4f%s\n", lod, nodes, double(bytes) / 1.0e6, s.gpu_ms,
                    ratio, s.neural_queries_per_ray(), s.neural_queries_per_second(), flip, noise ? " *" : "");
        rows.push_back({{"lod", lod}, {"nodes", nodes}, {"neural_bytes", bytes}, {"resident_bytes", mem.total()},
                        {"within_2x_floor", noise}, {"gpu_ms", s.gpu_ms},
                        {"wall_ms", s.wall_ms}, {"ratio_to_classical", ratio}, {"neural_queries", s.neural_queries},
                        {"queries_per_ray", s.neural_queries_per_ray()},
                        {"queries_per_second", s.neural_queries_per_second()}, {"query_gpu_ms", s.neural_query_ms},
                        {"pass_gpu_ms", pass_ms_json(s)}, {"pass_gpu_ms_by_depth", pass_depth_ms_json(s)},
                        {"flip", flip}});
    }
    std::printf("\nneural path %s\n", path_name.c_str());
    if (ctx.validation_enabled() && ctx.validation_message_count() > 0)
        log_warn("bench: %d Vulkan validation messages", ctx.validation_message_count());
    if (a.json.empty()) return;
    nlohmann::json j = {{"scene", a.scene}, {"model", a.model}, {"assets", model.assets.size()},
                        {"commit", build_commit()}, {"command_line", a.command_line},
                        {"vulkan_validation", ctx.validation_enabled()}, {"noise_floor", floor},
                        {"device", ref.stats.device}, {"driver", ref.stats.driver}, {"width", options.width},
                        {"height", options.height}, {"spp", options.spp}, {"max_depth", options.max_depth},
                        {"repeat", a.repeat}, {"neural_path", path_name},
                        {"sampler", render::sampler_name(options.sampler)},
                        {"flip_metric", "ldr: ACES tone map + 8-bit sRGB (as nbvh render PNGs), ppd 67.02; hybrid and "
                                        "reference share the seed"},
                        {"classical",
                         {{"gpu_ms", ref_ms}, {"wall_ms", ref.stats.wall_ms}, {"pass_gpu_ms", pass_ms_json(ref.stats)},
                          {"pass_gpu_ms_by_depth", pass_depth_ms_json(ref.stats)}}},
                        {"lods", rows}};
    write_text_atomically(a.json, j.dump(2) + "\n");
}

} // namespace

void add_bench_command(CLI::App& app, const std::string& command_line) {
    auto args = std::make_shared<BenchArgs>();
    args->command_line = command_line;
    auto* cmd = app.add_subcommand("bench", "time the classical reference and every N-BVH level of detail; FLIP of each");
    cmd->add_option("scene", args->scene, "glTF/GLB file, or 'default' for the built-in scene")->required();
    cmd->add_option("--model", args->model, "N-BVH model (.nbvh) of the scene's neural asset")->required();
    add_render_option_flags(cmd, args->options);
    cmd->add_option("--device", args->device, vk::DEVICE_OPTION_HELP);
    cmd->add_option("--repeat", args->repeat, "timed renders per configuration (the median is reported)")
        ->check(CLI::Range(1u, 1000u));
    cmd->add_option("--json", args->json, "write the table (and per-pass GPU times) as JSON");
    cmd->add_option("--neural-path", args->neural_path, "MLP implementation: auto, scalar or coopmat");
    cmd->add_option("--camera", args->camera, "eye_x,eye_y,eye_z,target_x,target_y,target_z,fov_deg");
    add_subdivide_option(cmd, args->subdivide);
    cmd->add_option("--env", args->env, "environment map (.hdr or .exr, equirectangular), or 'none' (the scene's lights only)");
    cmd->add_option("--env-rotation", args->env_rotation, "rotate the environment about +y by this many degrees")
        ->check(CLI::Range(-3600.0f, 3600.0f));
    cmd->callback([args] { run_bench(*args); });
}

} // namespace nbvh::app
