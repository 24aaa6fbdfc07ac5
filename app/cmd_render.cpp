// nbvh render SCENE [--out FILE.png|.exr] [--width --height --spp --max-depth --seed] [--device]
//                   [--camera ex,ey,ez,tx,ty,tz,fov] [--env FILE.hdr|.exr|none] [--exposure auto|STOPS]
//                   [--stats FILE.json] [--explain]
//                   [--model M.nbvh [--lod L] [--secondary-lod coarsest|same|L] [--neural-path auto|scalar|coopmat]]
//                   [--classical] [--neural GLOB] [--neural-roughness R] [--neural-metallic M]
//                   [--neural-max-leaves N] [--neural-batched-rounds N] [--wave-pixels N]
//                   [--texture-path auto|buffer|array]
// With --model the scene's neural instances are rendered from the model (hybrid); --classical renders
// them from their triangles with the same material constants (the reference FLIP compares against).
// Loads the scene, builds its BVHs, runs the wavefront path tracer (engine/render/) and writes the image
// (PNG: exposure (auto by default, engine/core/exposure.h), ACES-fit tone map + sRGB, engine/core/image.h;
// EXR: linear radiance).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/build_info.h"
#include "app/commands.h"
#include "app/output_path.h"
#include "app/render_args.h"
#include "app/render_measure.h"
#include "app/scene_arg.h"
#include "engine/bvh/scene_accel.h"
#include "engine/core/error.h"
#include "engine/core/exposure.h"
#include "engine/core/image.h"
#include "engine/core/log.h"
#include "engine/neural/model_file.h"
#include "engine/render/gpu_scene.h"
#include "engine/render/wavefront.h"
#include "engine/scene/camera.h"
#include "engine/scene/environment.h"
#include "engine/vk/context.h"

namespace nbvh::app {
namespace {

struct RenderArgs {
    std::string scene, out = "render.png", device = "auto", camera, env, stats, exposure = "auto";
    std::optional<float> env_rotation; // degrees
    std::string model, neural_path = "auto", neural_glob, texture_path = "auto", secondary_lod = "coarsest";
    render::RenderOptions options;
    bool explain = false;
    uint32_t subdivide = 0;   // flat midpoint subdivision levels of every mesh (engine/scene/subdivide.h)
    uint32_t warmup = 0;      // untimed renders of the same image before the one written
    std::string command_line; // as typed, written into --stats
};

// The exposure of the written image: PNG gets --exposure (auto: from the image), EXR stays linear.
struct Exposure {
    std::string mode; // "auto", "fixed" or "none" (EXR)
    float stops = 0.0f;
};

// What produced a --stats file: the binary's commit, the command and the settings that change the work
// or the image (defaults included, so that a results file says what "default" meant at its commit).
nlohmann::json settings_json(const RenderArgs& a, const render::RenderOptions& o) {
    nlohmann::json j = {{"seed", o.seed},
                        {"rr_start_depth", o.rr_start_depth},
                        {"sort_rays", o.sort_rays},
                        {"sampler", render::sampler_name(o.sampler)},
                        {"max_wave_pixels", o.max_wave_pixels},
                        {"texture_path", a.texture_path},
                        {"subdivide", a.subdivide},
                        {"warmup", a.warmup}};
    if (o.neural.model) {
        const render::NeuralRenderOptions& n = o.neural;
        j["neural"] = {{"model", a.model},
                       {"lod", n.lod},
                       {"secondary_lod", a.secondary_lod},
                       {"visibility_threshold", n.threshold},
                       {"max_leaves", n.max_rounds},
                       {"max_leaves_secondary", render::effective_secondary_leaves(n)},
                       {"max_leaves_shadow", render::effective_shadow_leaves(n)},
                       {"truncated_shadows_occlusion", n.truncated_shadows_occlusion},
                       {"leaves_per_round", n.leaves_per_round},
                       {"leaves_per_round_camera", n.leaves_per_round_camera},
                       {"batched_rounds", n.batched_rounds},
                       {"occupancy", n.occupancy},
                       {"materials", n.materials == render::NeuralMaterials::mix    ? "mix"
                                     : n.materials == render::NeuralMaterials::fit  ? "fit"
                                     : n.materials == render::NeuralMaterials::node ? "node"
                                                                                    : "asset"},
                       {"backface_escape", n.backface_escape},
                       {"query", n.split_query ? "split" : "fused"}, // requested; neural.path says what ran
                       {"split_min_pairs", n.split_min_pairs},
                       {"roughness_override", n.roughness},
                       {"metallic_override", n.metallic}};
    }
    j["classical_reference"] = o.neural.classical;
    return j;
}

void write_stats(const std::string& path, const render::RenderStats& s, const RenderArgs& a,
                 const render::RenderOptions& options, const Exposure& exposure) {
    nlohmann::json j;
    j["commit"] = build_commit();
    j["command_line"] = a.command_line;
    j["settings"] = settings_json(a, options);
    j["scene"] = a.scene;
    j["device"] = s.device;
    j["driver"] = s.driver;
    j["width"] = s.width;
    j["height"] = s.height;
    j["spp"] = s.spp;
    j["max_depth"] = s.max_depth;
    j["pass_gpu_ms"] = pass_ms_json(s);
    j["pass_gpu_ms_by_depth"] = pass_depth_ms_json(s);
    j["gpu_total_ms"] = s.gpu_ms;
    j["wall_ms"] = s.wall_ms;
    j["rays"] = {{"primary", s.rays_primary}, {"secondary", s.rays_secondary}, {"shadow", s.rays_shadow},
                 {"total", s.rays_total()}};
    j["rays_by_depth"] = {{"path", s.rays_by_depth}, {"shadow", s.shadow_rays_by_depth}};
    j["rays_per_second"] = s.rays_per_second();
    j["non_finite_samples"] = s.nonfinite_samples;
    j["non_finite_pixels"] = s.nonfinite_pixels;
    j["textures"] = {{"path", s.texture_path}, {"count", s.texture_count}, {"gpu_bytes", s.texture_bytes},
                     {"halvings", s.texture_halvings}};
    j["exposure"] = {{"mode", exposure.mode}, {"stops", exposure.stops}};
    if (!s.neural_path.empty()) {
        nlohmann::json n;
        n["path"] = s.neural_path;
        n["queries"] = s.neural_queries;
        n["queries_by_depth"] = s.neural_queries_by_depth; // with pass_gpu_ms_by_depth: queries/s per bounce
        n["rounds"] = s.neural_rounds;
        n["leaf_cap_rays"] = s.neural_leaf_cap_rays;
        n["queries_per_ray"] = s.neural_queries_per_ray();
        n["query_gpu_ms"] = s.neural_query_ms;
        n["queries_per_second"] = s.neural_queries_per_second();
        j["neural"] = n;
    }
    write_text_atomically(path, j.dump(2) + "\n");
}

void run_render(const RenderArgs& a) {
    if (!is_png_path(a.out) && !is_exr_path(a.out))
        throw Error(strfmt("--out '%s': expected a .png or .exr file name", a.out.c_str()));
    // Everything that can be checked cheaply is checked before the scene is loaded and rendered.
    const std::vector<std::string> inputs = {a.scene, a.env, a.model};
    check_output_path(a.out, "--out", inputs);
    check_output_path(a.stats, "--stats", inputs);
    const std::optional<float> fixed_exposure = parse_exposure(a.exposure);
    const render::TexturePathRequest texture_path = render::parse_texture_path(a.texture_path);
    const int32_t secondary_lod = parse_secondary_lod(a.secondary_lod);
    if (fixed_exposure && is_exr_path(a.out))
        log_warn("render: --exposure is ignored for EXR output (linear radiance, unscaled)");
    vk::ContextOptions copt;
    copt.set_device(a.device);
    SceneLoadOptions lo;
    lo.neural_glob = a.neural_glob;
    lo.subdivide = a.subdivide;
    render::RenderOptions options = a.options;
    options.texture_path = texture_path;
    options.neural.secondary_lod = secondary_lod;
    NeuralModel model;
    if (!a.model.empty()) model = load_model(a.model);
    // With a model (also for --classical: the same instances, from their triangles) its asset table
    // decides which instances are neural.
    Scene scene = load_scene_for_model(a.scene, lo, a.model.empty() ? nullptr : &model, a.model);
    if (!a.model.empty() && !options.neural.classical) options.neural.model = &model;
    options.neural.keep_neural_triangles = false; // one render, never switched to the classical reference
    options.neural.path = render::parse_neural_path(a.neural_path);
    Environment env = choose_environment(scene, a.env);
    if (a.env_rotation) env.rotation = *a.env_rotation * 3.14159265358979f / 180.0f;
    const Camera camera = choose_camera(scene, a.camera, a.options);
    if (a.explain) {
        // A hybrid render's neural stage and the texture path are chosen on the device, as the renderer
        // chooses them.
        const render::SceneFeatures features = render::derive_features(scene, env, options.neural);
        std::optional<vk::Context> ectx;
        if (options.neural.model || features.textures) ectx.emplace(copt);
        const auto plan = render::plan_neural(ectx ? &*ectx : nullptr, scene, options.neural);
        std::optional<render::TexturePlan> textures;
        if (ectx)
            textures = render::plan_textures(render::texture_caps(ectx->features()), scene, features.textures,
                                             options.texture_path);
        std::printf("%s", render::explain(features, options.max_depth, plan ? &*plan : nullptr,
                                          textures ? &*textures : nullptr).c_str());
        return;
    }
    vk::Context ctx(copt); // before the BVH build: a missing device fails fast
    const auto t0 = std::chrono::steady_clock::now();
    // A hybrid render leaves the meshes only the model answers for on the host (keep_neural_triangles
    // false above), so their BLAS is never read: their instances get their bounds only.
    const std::vector<bool> bounds_only =
        options.neural.model ? render::omitted_neural_meshes(scene) : std::vector<bool>();
    const SceneAccel accel = build_scene_accel_bounds_only(scene, bounds_only);
    log_info("render: BVHs built in %.1f ms%s",
             std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count(),
             std::count(bounds_only.begin(), bounds_only.end(), true) > 0
                 ? " (the neural-only meshes' bounds only: the model answers for them)"
                 : "");
    render::WavefrontRenderer renderer(ctx, scene, accel, env, camera, options);
    // --warmup: the same image rendered first, untimed. A GPU left idle by a long CPU phase (a large
    // scene's BVH build) starts at low clocks: an H200's 16-spp 1080p frames ran 3-5x slow right after
    // a 4-17 s build (results/perf/dense/README.md).
    for (uint32_t i = 0; i < a.warmup; ++i) (void)renderer.render();
    render::RenderResult result = renderer.render();
    const render::RenderStats& s = result.stats;
    log_info("render: %ux%u, %u spp on %s: %.1f ms GPU, %.3g rays/s, %llu non-finite pixels", s.width, s.height,
             s.spp, s.device.c_str(), s.gpu_ms, s.rays_per_second(), (unsigned long long)s.nonfinite_pixels);
    if (s.texture_path != "none")
        log_info("render: textures: %s", render::describe(renderer.texture_plan()).c_str());
    if (!s.neural_path.empty())
        log_info(
            "render: neural %s: %llu queries (%.2f per ray), %.3g queries/s over %.2f ms of query passes; "
            "%llu rays spent their leaf budget (--neural-max-leaves, --neural-max-leaves-secondary)",
            s.neural_path.c_str(), (unsigned long long)s.neural_queries, s.neural_queries_per_ray(),
            s.neural_queries_per_second(), s.neural_query_ms, (unsigned long long)s.neural_leaf_cap_rays);
    Exposure exposure{"none", 0.0f};
    if (is_exr_path(a.out)) {
        save_exr(a.out, convert_channels(result.image, 3));
    } else {
        PngEncode enc;
        enc.tone_map = ToneMap::aces;
        if (fixed_exposure) {
            exposure = {"fixed", *fixed_exposure};
        } else {
            const AutoExposure ae = auto_exposure(result.image);
            exposure = {"auto", ae.stops};
            log_info("render: exposure %+.2f stops (auto: key luminance %.4g of %zu lit pixels, 99th percentile "
                     "%.4g; --exposure 0 for none)", ae.stops, ae.key, ae.lit_pixels, ae.bright);
        }
        enc.exposure = exposure.stops;
        save_png(a.out, result.image, enc);
    }
    if (!a.stats.empty()) write_stats(a.stats, s, a, options, exposure);
    if (ctx.validation_enabled() && ctx.validation_message_count() > 0)
        log_warn("render: %d Vulkan validation messages", ctx.validation_message_count());
}

} // namespace

void add_render_command(CLI::App& app, const std::string& command_line) {
    auto args = std::make_shared<RenderArgs>();
    args->command_line = command_line;
    auto* cmd = app.add_subcommand("render", "path-trace a glTF scene (or 'default') with the wavefront renderer");
    cmd->add_option("scene", args->scene, "glTF/GLB file, or 'default' for the built-in scene")->required();
    cmd->add_option("--out", args->out, "output image: .png (tone-mapped sRGB) or .exr (linear)");
    add_render_option_flags(cmd, args->options); // --width --height --spp --max-depth --seed, neural constants
    cmd->add_option("--device", args->device, vk::DEVICE_OPTION_HELP);
    cmd->add_option("--camera", args->camera, "eye_x,eye_y,eye_z,target_x,target_y,target_z,fov_deg");
    cmd->add_option("--env", args->env,
                    "environment map (.hdr or .exr, equirectangular), or 'none' for the scene's own emitters and "
                    "lights only (default: the scene's environment, else the default sky)");
    cmd->add_option("--exposure", args->exposure,
                    "PNG exposure in stops, or 'auto' (default): from the image's key luminance; printed and in "
                    "--stats. EXR output is linear and unscaled");
    cmd->add_option("--env-rotation", args->env_rotation, "rotate the environment about +y by this many degrees")
        ->check(CLI::Range(-3600.0f, 3600.0f));
    cmd->add_option("--stats", args->stats, "write per-pass GPU times, ray counts and checks as JSON, with the commit, command line and settings");
    cmd->add_flag("--explain", args->explain, "print the scene's feature set and the passes, then exit");
    cmd->add_option("--model", args->model, "N-BVH model (.nbvh) for the scene's neural instances (hybrid render)");
    cmd->add_flag("--classical", args->options.neural.classical,
                  "reference: the true scene (neural instances from their triangles and glTF materials)");
    cmd->add_option("--neural", args->neural_glob, "nodes whose name matches this glob are neural instances");
    cmd->add_option(
           "--warmup", args->warmup,
           "render the image this many times first, untimed, in the same process (GPU clocks and caches "
           "settle before the timed render that is written; for benchmarks)")
        ->check(CLI::Range(0u, 16u));
    add_subdivide_option(cmd, args->subdivide);
    cmd->add_option("--lod", args->options.neural.lod, "N-BVH level of detail of camera rays (0 = finest)");
    cmd->add_option("--secondary-lod", args->secondary_lod,
                    "N-BVH level of detail after the first hit: coarsest (default: the model's coarsest LoD, "
                    "never finer than --lod; = --lod for a one-LoD model), same (as --lod) or 0..7");
    cmd->add_option("--neural-path", args->neural_path, "MLP implementation: auto, scalar or coopmat");
    cmd->add_option("--texture-path", args->texture_path,
                    "textures as one texel buffer (any device), an array of images (descriptor indexing), or "
                    "auto (default): the array where the device has it; --explain and --stats say which ran");
    cmd->callback([args] { run_render(*args); });
}

} // namespace nbvh::app
