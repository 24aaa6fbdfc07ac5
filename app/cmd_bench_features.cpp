// nbvh bench-features SCENE... [--width --height --spp --max-depth --seed] [--repeat R] [--device]
//                               [--env FILE|none] [--json FILE.json] [--markdown FILE.md]
// What simulating only the effects a scene calls for saves (issue 12, ARCHITECTURE.md "Simulate only the
// effects a scene calls for"). Per scene (a glTF file or 'default', lit as `nbvh render` lights it): the
// frame time of its own specialization (render::derive_features), with every forcible effect forced on
// (textures, normal maps, emission NEE, environment NEE, alpha test, transmission, punctual lights,
// single-sided culling: RenderOptions::forced_features), and with each effect the scene lacks forced on
// alone; the time saved is forced minus own. Frame time: GPU timestamps summed over the passes of one
// frame (spp samples), the median of R frames after a warm-up, the configurations of a scene rendered in
// turn frame by frame (clock drift hits all alike). Forcing must not change the image: the own and the
// all-forced images are compared (LDR-FLIP at the own image's auto exposure, beside the noise floor: the
// own render with another seed), and the command fails when they differ by more than a tenth of the floor.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
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
#include "engine/core/flip.h"
#include "engine/core/log.h"
#include "engine/render/feature_set.h"
#include "engine/render/wavefront.h"
#include "engine/vk/context.h"

namespace nbvh::app {
namespace {

// The own image and the all-forced one agree when their FLIP is below this fraction of the noise floor:
// shared random numbers make them equal up to floating-point rounding (feature_force_test.cpp), while a
// forcing that changed the sampling gives a FLIP of the order of the floor.
constexpr double AGREE_FRACTION_OF_FLOOR = 0.1;

struct Args {
    std::vector<std::string> scenes;
    std::string device = "auto", env, json, markdown, command_line;
    uint32_t repeat = 9;
    render::RenderOptions options;
    Args() {
        options.width = 1920;
        options.height = 1080;
        options.spp = 4; // the frame figures of results/ are 4 spp
    }
};

struct Config {
    std::string name;             // "own", "all", or the one forced feature
    render::SceneFeatures forced; // RenderOptions::forced_features
    std::unique_ptr<render::WavefrontRenderer> renderer;
    std::vector<double> gpu_ms;
    double median_ms = 0.0;
    render::RenderStats stats;    // of the last frame
};

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

// Pixels whose RGB differs by more than 1e-3 of the image's mean luminance (a path that diverged).
double fraction_differing(const Image& a, const Image& b) {
    double mean = 0.0;
    for (size_t i = 0; i < a.pixel_count(); ++i)
        mean += 0.2126 * a.data[i * 4] + 0.7152 * a.data[i * 4 + 1] + 0.0722 * a.data[i * 4 + 2];
    mean = std::max(mean / double(std::max<size_t>(1, a.pixel_count())), 1.0e-6);
    size_t n = 0;
    for (size_t i = 0; i < a.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c)
            if (std::fabs(double(a.data[i * 4 + c]) - double(b.data[i * 4 + c])) > 1.0e-3 * mean) {
                ++n;
                break;
            }
    return double(n) / double(std::max<size_t>(1, a.pixel_count()));
}

std::string feature_list(const render::SceneFeatures& f) {
    std::string s;
    for (const render::ForcibleFeature& x : render::forcible_features())
        if (f.*x.flag) s += (s.empty() ? "" : ", ") + std::string(x.name);
    return s.empty() ? "none" : s;
}

nlohmann::json bench_scene(const vk::Context& ctx, const Args& a, const std::string& scene_arg, bool& all_agree) {
    const std::string name = std::filesystem::path(scene_arg).stem().string(); // "default" stays
    const Scene scene = load_scene_arg(scene_arg);
    const Environment env = choose_environment(scene, a.env);
    const Camera camera = choose_camera(scene, "", a.options);
    const SceneAccel accel = build_scene_accel(scene);
    size_t triangles = 0;
    for (const Instance& inst : scene.instances)
        if (inst.mesh < scene.meshes.size()) triangles += scene.meshes[inst.mesh].indices.size() / 3;

    std::vector<Config> configs;
    configs.push_back({"own", {}, nullptr, {}, 0.0, {}});
    configs.push_back({"all", render::all_forcible_features(), nullptr, {}, 0.0, {}});
    for (Config& c : configs) {
        render::RenderOptions o = a.options;
        o.forced_features = c.forced;
        c.renderer = std::make_unique<render::WavefrontRenderer>(ctx, scene, accel, env, camera, o);
    }
    const render::SceneFeatures own = configs[0].renderer->features();
    for (const render::ForcibleFeature& x : render::forcible_features()) {
        if (own.*x.flag) continue;
        Config c{x.name, {}, nullptr, {}, 0.0, {}};
        c.forced.*x.flag = true;
        render::RenderOptions o = a.options;
        o.forced_features = c.forced;
        c.renderer = std::make_unique<render::WavefrontRenderer>(ctx, scene, accel, env, camera, o);
        configs.push_back(std::move(c));
    }
    log_info("bench-features: %s: %zu instanced triangles, features: %s; %zu configurations x %u frames",
             scene_arg.c_str(), triangles, feature_list(own).c_str(), configs.size(), a.repeat);
    for (Config& c : configs) c.renderer->render(); // warm-up: pipelines, caches, clocks
    for (uint32_t r = 0; r < a.repeat; ++r)
        for (Config& c : configs) {
            c.stats = c.renderer->render().stats;
            c.gpu_ms.push_back(c.stats.gpu_ms);
        }
    for (Config& c : configs) c.median_ms = median(c.gpu_ms);

    // Images: the own render, the all-forced one (same seed), and the own with another seed (noise floor).
    const Image own_img = configs[0].renderer->read_output();
    const Image all_img = configs[1].renderer->read_output();
    render::RenderOptions floor_opt = a.options;
    floor_opt.seed = a.options.seed + 1;
    NBVH_CHECK(configs[0].renderer->apply(floor_opt));
    const Image floor_img = configs[0].renderer->render().image;
    const float stops = auto_exposure(own_img).stops;
    const Image own_px = as_png_pixels(own_img, stops);
    const double flip_all = flip_ldr(own_px, as_png_pixels(all_img, stops)).mean;
    const double floor = flip_ldr(own_px, as_png_pixels(floor_img, stops)).mean;
    const bool agree = flip_all <= AGREE_FRACTION_OF_FLOOR * floor;
    all_agree = all_agree && agree;

    const double own_ms = configs[0].median_ms, all_ms = configs[1].median_ms;
    std::printf("%-24s own %8.3f ms  all forced %8.3f ms  saved %7.3f ms (%5.1f %%)  FLIP own/all %.5f "
                "(floor %.4f)%s\n",
                name.c_str(), own_ms, all_ms, all_ms - own_ms, all_ms > 0.0 ? 100.0 * (all_ms - own_ms) / all_ms : 0.0,
                flip_all, floor, agree ? "" : "  IMAGES DIFFER");
    nlohmann::json per_feature = nlohmann::json::array();
    for (const render::ForcibleFeature& x : render::forcible_features()) {
        nlohmann::json f = {{"feature", x.name}, {"in_scene", bool(own.*x.flag)}};
        for (const Config& c : configs)
            if (c.name == x.name) {
                f["forced_ms"] = c.median_ms;
                f["saved_ms"] = c.median_ms - own_ms;
                f["pixels_differing"] = fraction_differing(own_img, c.renderer->read_output());
                std::printf("    %-14s forced alone %8.3f ms  saved %7.3f ms\n", x.name, c.median_ms, c.median_ms - own_ms);
            }
        per_feature.push_back(f);
    }
    nlohmann::json frames = nlohmann::json::object();
    for (const Config& c : configs) frames[c.name] = c.gpu_ms;
    return {{"scene", scene_arg},
            {"name", name},
            {"instanced_triangles", triangles},
            {"features", feature_list(own)},
            {"shadow_pass", own.has_lights()},
            {"own_ms", own_ms},
            {"all_forced_ms", all_ms},
            {"saved_ms", all_ms - own_ms},
            {"saved_fraction", all_ms > 0.0 ? (all_ms - own_ms) / all_ms : 0.0},
            {"own_pass_gpu_ms", pass_ms_json(configs[0].stats)},
            {"all_forced_pass_gpu_ms", pass_ms_json(configs[1].stats)},
            {"per_feature", per_feature},
            {"images", {{"flip_own_vs_all_forced", flip_all}, {"noise_floor", floor}, {"agree", agree},
                        {"pixels_differing", fraction_differing(own_img, all_img)}, {"exposure_stops", stops}}},
            {"frames_gpu_ms", frames}};
}

std::string markdown_table(const nlohmann::json& scenes) {
    std::string s = "| scene | its features | own ms | all forced ms | saved |";
    std::string rule = "| --- | --- | ---: | ---: | ---: |";
    for (const render::ForcibleFeature& x : render::forcible_features()) {
        s += std::string(" ") + x.name + " |";
        rule += " ---: |";
    }
    s += " FLIP own vs all (floor) |\n" + rule + " ---: |\n";
    for (const nlohmann::json& j : scenes) {
        s += strfmt("| %s | %s | %.3f | %.3f | %.3f ms (%.1f %%) |", j["name"].get<std::string>().c_str(),
                    j["features"].get<std::string>().c_str(), j["own_ms"].get<double>(),
                    j["all_forced_ms"].get<double>(), j["saved_ms"].get<double>(),
                    100.0 * j["saved_fraction"].get<double>());
        for (const nlohmann::json& f : j["per_feature"])
            s += f["in_scene"].get<bool>() ? std::string(" used |") : strfmt(" %+.3f |", f["saved_ms"].get<double>());
        s += strfmt(" %.5f (%.4f) |\n", j["images"]["flip_own_vs_all_forced"].get<double>(),
                    j["images"]["noise_floor"].get<double>());
    }
    return s;
}

void write_results(const Args& a, const std::string& device, const std::string& driver, const nlohmann::json& scenes);

void run_bench_features(const Args& a) {
    check_output_path(a.json, "--json", a.scenes);
    check_output_path(a.markdown, "--markdown", a.scenes);
    if (!a.json.empty() && a.json == a.markdown) throw Error("--json and --markdown name the same file");
    vk::ContextOptions copt;
    copt.set_device(a.device);
    vk::Context ctx(copt);
    const std::string device = ctx.features().device_name;
    const std::string driver = ctx.features().driver_name + " " + ctx.features().driver_info;
    std::printf("device %s (driver %s), %ux%u, %u spp, max depth %u, median of %u frames after a warm-up\n",
                device.c_str(), driver.c_str(), a.options.width, a.options.height, a.options.spp, a.options.max_depth,
                a.repeat);
    nlohmann::json scenes = nlohmann::json::array();
    bool agree = true;
    for (const std::string& scene : a.scenes) {
        scenes.push_back(bench_scene(ctx, a, scene, agree));
        write_results(a, device, driver, scenes); // after every scene: a run cut short keeps what it measured
    }
    if (!agree) throw Error("the all-forced image differs from the own one (see FLIP own/all): a forcing is wrong");
}

void write_results(const Args& a, const std::string& device, const std::string& driver, const nlohmann::json& scenes) {
    if (!a.json.empty()) {
        const nlohmann::json j = {{"device", device}, {"driver", driver}, {"commit", build_commit()},
                                  {"command_line", a.command_line}, {"width", a.options.width},
                                  {"height", a.options.height}, {"spp", a.options.spp},
                                  {"max_depth", a.options.max_depth}, {"repeat", a.repeat},
                                  {"frame_ms", "GPU timestamps summed over the passes of one frame, median"},
                                  {"saved_ms", "forced minus own"}, {"scenes", scenes}};
        write_text_atomically(a.json, j.dump(2) + "\n");
    }
    if (!a.markdown.empty())
        write_text_atomically(a.markdown, strfmt("Device %s (driver %s), commit %s, %ux%u, %u spp, max depth %u, "
                                                 "median of %u frames.\n\n",
                                                 device.c_str(), driver.c_str(), build_commit(), a.options.width,
                                                 a.options.height, a.options.spp, a.options.max_depth, a.repeat) +
                                              markdown_table(scenes));
}

} // namespace

void add_bench_features_command(CLI::App& app, const std::string& command_line) {
    auto args = std::make_shared<Args>();
    args->command_line = command_line;
    auto* cmd = app.add_subcommand("bench-features",
                                   "time each scene with its own specialization and with every effect forced on");
    cmd->add_option("scenes", args->scenes, "glTF/GLB files, or 'default' for the built-in scene")->required();
    cmd->add_option("--width", args->options.width, "image width in pixels")->check(CLI::Range(1u, 16384u));
    cmd->add_option("--height", args->options.height, "image height in pixels")->check(CLI::Range(1u, 16384u));
    cmd->add_option("--spp", args->options.spp, "samples per pixel of one frame")->check(CLI::Range(1u, 1u << 16));
    cmd->add_option("--max-depth", args->options.max_depth, "maximum path segments")->check(CLI::Range(1u, 256u));
    cmd->add_option("--seed", args->options.seed, "random seed");
    cmd->add_option("--repeat", args->repeat, "timed frames per configuration (the median is reported)")
        ->check(CLI::Range(1u, 1000u));
    cmd->add_option("--device", args->device, vk::DEVICE_OPTION_HELP);
    cmd->add_option("--env", args->env, "environment map (.hdr or .exr), or 'none' (the scene's lights only)");
    cmd->add_option("--json", args->json, "write every figure (and the frames' GPU times) as JSON");
    cmd->add_option("--markdown", args->markdown, "write the table as markdown");
    cmd->callback([args] { run_bench_features(*args); });
}

} // namespace nbvh::app
