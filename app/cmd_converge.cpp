// nbvh converge SCENE --model M.nbvh [--from N] [--spp N] [--ref-spp N] [--width --height --max-depth --seed]
//                     [--lod L] [--secondary-lod ...] [--camera] [--env] [--exposure] [--device] [--json F] [--csv F]
// How far a hybrid-vs-classical FLIP is from the converged one (issue 11: "shared random numbers may cut
// the spp needed if you show they give the same answer as converged images"). In one process on one
// device: a classical reference of the true scene at --ref-spp (its own seed), then the classical image
// and the hybrid image with one seed, both extended sample by sample (one film each, progressive) and
// compared at every doubling from --from to --spp:
//   noise floor   FLIP(reference, classical@N)      how much noise alone reads as error at N spp
//   independent   FLIP(reference, hybrid@N)         the study's FLIP: error + noise
//   shared seed   FLIP(classical@N, hybrid@N)       the two images share their random numbers
//   less floor    sqrt(independent^2 - floor^2)     the independent FLIP with the noise taken out in quadrature
// As N grows both images converge, so the shared-seed FLIP and the independent one meet the converged
// error; the table shows at which N the shared-seed FLIP has stopped moving, i.e. from which spp it can
// stand for the converged figure. Images as `nbvh render` writes PNGs (ACES, 8-bit sRGB) at the
// reference's exposure.
#include <algorithm>
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
#include "app/study/study_options.h"
#include "engine/bvh/scene_accel.h"
#include "engine/core/error.h"
#include "engine/core/exposure.h"
#include "engine/core/flip.h"
#include "engine/core/image.h"
#include "engine/core/log.h"
#include "engine/neural/model_file.h"
#include "engine/render/wavefront.h"
#include "engine/vk/context.h"

namespace nbvh::app {
namespace {

struct ConvergeArgs {
    std::string scene, model, device = "auto", json, csv, neural_path = "auto", camera, env, exposure = "auto",
                                              secondary_lod = "coarsest", command_line;
    std::optional<float> env_rotation; // degrees
    uint32_t from = 128, lod = 0;
    uint32_t subdivide = 0;            // --subdivide (engine/scene/subdivide.h)
    std::optional<uint32_t> ref_spp;   // default 4 x --spp
    render::RenderOptions options;
    ConvergeArgs() {
        options.width = 960; // the study's image size
        options.height = 540;
        options.spp = 8192;
    }
};

struct Row {
    uint32_t spp = 0;
    double floor = 0.0, independent = 0.0, shared = 0.0, less_floor = 0.0;
    double classical_gpu_ms = 0.0, hybrid_gpu_ms = 0.0; // of the samples added for this row
};

// from, 2 from, 4 from, ... below spp, then spp.
std::vector<uint32_t> checkpoints(uint32_t from, uint32_t spp) {
    std::vector<uint32_t> out;
    for (uint64_t n = from; n < spp; n *= 2) out.push_back(uint32_t(n));
    out.push_back(spp);
    return out;
}

void check_args(const ConvergeArgs& a) {
    check_output_path(a.json, "--json", {a.scene, a.model, a.env});
    check_output_path(a.csv, "--csv", {a.scene, a.model, a.env});
    if (!a.json.empty() && a.json == a.csv) throw Error("--json and --csv name the same file");
    if (a.from == 0) throw Error("--from must be at least 1");
    if (a.options.spp < a.from)
        throw Error(strfmt("--spp %u is below --from %u (the compared spp run from --from to --spp)",
                           a.options.spp, a.from));
    if (a.ref_spp && *a.ref_spp < a.options.spp)
        throw Error(strfmt("--ref-spp %u is below --spp %u (the reference must be the most converged image)",
                           *a.ref_spp, a.options.spp));
}

std::string csv_text(const std::vector<Row>& rows) {
    std::string s = "spp,noise_floor,flip,flip_same_seed,flip_less_floor,classical_gpu_ms,hybrid_gpu_ms\n";
    for (const Row& r : rows)
        s += strfmt("%u,%.6f,%.6f,%.6f,%.6f,%.3f,%.3f\n", r.spp, r.floor, r.independent, r.shared, r.less_floor,
                    r.classical_gpu_ms, r.hybrid_gpu_ms);
    return s;
}

void run_converge(const ConvergeArgs& a) {
    check_args(a);
    const uint32_t ref_spp = a.ref_spp.value_or(uint32_t(std::min<uint64_t>(4ull * a.options.spp, 1u << 20)));
    const std::optional<float> fixed_exposure = parse_exposure(a.exposure);
    vk::ContextOptions copt;
    copt.set_device(a.device);
    render::RenderOptions base = a.options;
    base.neural.path = render::parse_neural_path(a.neural_path);
    base.neural.lod = a.lod;
    base.neural.secondary_lod = parse_secondary_lod(a.secondary_lod);
    const ModelScene ms =
        load_model_scene(a.scene, a.model, a.env, a.env_rotation, a.camera, base, a.subdivide);
    const NeuralModel& model = ms.model;
    const Scene& scene = ms.scene;
    const Environment& env = ms.env;
    const Camera& camera = ms.camera;
    if (a.lod >= std::max(1u, model.lod_count))
        throw Error(strfmt("--lod %u: the model has %u level(s) of detail", a.lod, std::max(1u, model.lod_count)));
    render::RenderOptions classical = base;
    classical.neural.classical = true;
    render::validate(classical.neural, scene);
    render::RenderOptions hybrid = base;
    hybrid.neural.model = &model;
    render::validate(hybrid.neural, scene);
    vk::Context ctx(copt);
    const SceneAccel accel = build_scene_accel(scene);

    // The reference: the true scene at ref_spp with its own seed.
    render::RenderOptions ref_opt = classical;
    ref_opt.spp = ref_spp;
    ref_opt.seed = base.seed + STUDY_REFERENCE_SEED_OFFSET;
    log_info("converge: classical reference, %u spp", ref_spp);
    const render::RenderResult ref = [&] {
        render::WavefrontRenderer r(ctx, scene, accel, env, camera, ref_opt);
        return r.render();
    }();
    const float exposure = fixed_exposure ? *fixed_exposure : auto_exposure(ref.image).stops;
    const FlipReference ref_flip(as_png_pixels(ref.image, exposure)); // prepared once for every row

    // The compared pair: one seed, one film each, extended to every checkpoint.
    render::WavefrontRenderer c(ctx, scene, accel, env, camera, classical);
    render::WavefrontRenderer h(ctx, scene, accel, env, camera, hybrid);
    std::vector<Row> rows;
    std::string neural_path;
    uint32_t done = 0;
    std::printf("device      %s (driver %s)\n", ref.stats.device.c_str(), ref.stats.driver.c_str());
    std::printf("scene       %s, %ux%u, max depth %u, LoD %u, secondary %s; reference %u spp (seed %u), "
                "compared images seed %u, exposure %+.2f stops\n",
                a.scene.c_str(), base.width, base.height, base.max_depth, a.lod, a.secondary_lod.c_str(), ref_spp,
                ref_opt.seed, base.seed, exposure);
    std::printf("FLIP        LDR-FLIP of the PNG pixels; floor = reference vs classical, independent = reference vs "
                "hybrid, shared seed = classical vs hybrid (same seed), less floor = sqrt(independent^2 - floor^2)\n\n");
    std::printf("%8s %12s %12s %12s %12s %14s %14s\n", "spp", "noise floor", "independent", "shared seed",
                "less floor", "classical ms", "hybrid ms");
    for (uint32_t n : checkpoints(a.from, a.options.spp)) {
        Row r;
        r.spp = n;
        const render::RenderResult rc = c.render_progressive(n - done);
        const render::RenderResult rh = h.render_progressive(n - done);
        done = n;
        neural_path = rh.stats.neural_path;
        r.classical_gpu_ms = rc.stats.gpu_ms;
        r.hybrid_gpu_ms = rh.stats.gpu_ms;
        const Image cp = as_png_pixels(rc.image, exposure), hp = as_png_pixels(rh.image, exposure);
        r.floor = ref_flip.compare(cp).mean;
        r.independent = ref_flip.compare(hp).mean;
        r.shared = flip_ldr(cp, hp).mean;
        r.less_floor = std::sqrt(std::max(0.0, r.independent * r.independent - r.floor * r.floor));
        for (double v : {r.floor, r.independent, r.shared})
            if (!std::isfinite(v)) throw Error(strfmt("converge: a non-finite FLIP at %u spp", n));
        rows.push_back(r);
        std::printf("%8u %12.4f %12.4f %12.4f %12.4f %14.1f %14.1f\n", n, r.floor, r.independent, r.shared,
                    r.less_floor, r.classical_gpu_ms, r.hybrid_gpu_ms);
        std::fflush(stdout);
    }
    const Row& last = rows.back();
    std::printf("\nshared seed at %u spp vs at %u spp: %+.4f; the reference's own floor is the last row's (%.4f)\n",
                rows.front().spp, last.spp, rows.front().shared - last.shared, last.floor);
    if (ctx.validation_enabled() && ctx.validation_message_count() > 0)
        log_warn("converge: %d Vulkan validation messages", ctx.validation_message_count());

    if (!a.csv.empty()) write_text_atomically(a.csv, csv_text(rows));
    if (a.json.empty()) return;
    nlohmann::json jr = nlohmann::json::array();
    for (const Row& r : rows)
        jr.push_back({{"spp", r.spp}, {"noise_floor", r.floor}, {"flip", r.independent}, {"flip_same_seed", r.shared},
                      {"flip_less_floor", r.less_floor}, {"classical_gpu_ms", r.classical_gpu_ms},
                      {"hybrid_gpu_ms", r.hybrid_gpu_ms}});
    const nlohmann::json j = {
        {"tool", "nbvh converge (issue 11)"},
        {"scene", a.scene},
        {"model", a.model},
        {"commit", build_commit()},
        {"command_line", a.command_line},
        {"device", ref.stats.device},
        {"driver", ref.stats.driver},
        {"vulkan_validation", ctx.validation_enabled()},
        {"width", base.width},
        {"height", base.height},
        {"max_depth", base.max_depth},
        {"lod", a.lod},
        {"secondary_lod", a.secondary_lod},
        {"neural_path", neural_path},
        {"sampler", render::sampler_name(base.sampler)},
        {"seed", base.seed},
        {"reference_seed", ref_opt.seed},
        {"ref_spp", ref_spp},
        {"reference_gpu_ms", ref.stats.gpu_ms},
        {"exposure_stops", exposure},
        {"flip_metric", "LDR-FLIP (ppd 67.02) of ACES-tone-mapped 8-bit sRGB images at the reference's exposure"},
        {"rows", jr}};
    write_text_atomically(a.json, j.dump(1) + "\n");
}

} // namespace

void add_converge_command(CLI::App& app, const std::string& command_line) {
    auto args = std::make_shared<ConvergeArgs>();
    args->command_line = command_line;
    auto* cmd = app.add_subcommand(
        "converge", "how far hybrid-vs-classical FLIP is from converged: noise floor, independent and shared-seed "
                    "FLIP at every doubling of spp");
    cmd->add_option("scene", args->scene, "glTF/GLB file, or 'default' for the built-in scene")->required();
    cmd->add_option("--model", args->model, "N-BVH model (.nbvh) of the scene's neural assets")->required();
    add_render_option_flags(cmd, args->options); // --spp: the largest compared spp (default 8192)
    cmd->add_option("--from", args->from, "the smallest compared spp (then doubled up to --spp)")
        ->check(CLI::Range(1u, 1u << 20));
    cmd->add_option("--ref-spp", args->ref_spp, "samples per pixel of the classical reference (default 4 x --spp)")
        ->check(CLI::Range(1u, 1u << 20));
    cmd->add_option("--lod", args->lod, "N-BVH level of detail of camera rays (0 = finest)");
    cmd->add_option("--secondary-lod", args->secondary_lod, "LoD after the first hit: coarsest, same or 0..7");
    cmd->add_option("--device", args->device, vk::DEVICE_OPTION_HELP);
    cmd->add_option("--json", args->json, "write the table as JSON (device, commit, command line inside)");
    cmd->add_option("--csv", args->csv, "write the table as CSV");
    cmd->add_option("--neural-path", args->neural_path, "MLP implementation: auto, scalar or coopmat");
    cmd->add_option("--camera", args->camera, "eye_x,eye_y,eye_z,target_x,target_y,target_z,fov_deg");
    add_subdivide_option(cmd, args->subdivide);
    cmd->add_option("--env", args->env, "environment map (.hdr or .exr), or 'none' (the scene's lights only)");
    cmd->add_option("--env-rotation", args->env_rotation, "rotate the environment about +y by this many degrees")
        ->check(CLI::Range(-3600.0f, 3600.0f));
    cmd->add_option("--exposure", args->exposure, "stops of every compared PNG, or auto (the reference's)");
    cmd->callback([args] { run_converge(*args); });
}

} // namespace nbvh::app
