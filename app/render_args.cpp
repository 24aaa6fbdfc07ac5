#include "app/render_args.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "app/scene_arg.h"
#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/scene/camera.h"
#include "engine/scene/environment.h"
#include "engine/scene/subdivide.h"

namespace nbvh::app {

namespace {

// --neural-truncated-shadows block|pass|P: the probability that a truncated shadow ray is occluded, or
// -1 for a word that is none of them (the whole word a number in [0, 1]).
float truncated_shadows_occlusion(const std::string& v) {
    if (v == "block") return 1.0f;
    if (v == "pass") return 0.0f;
    size_t used = 0;
    float p = -1.0f;
    try {
        p = std::stof(v, &used);
    } catch (const std::exception&) {
        return -1.0f;
    }
    return used == v.size() && p >= 0.0f && p <= 1.0f ? p : -1.0f;
}

// --sampler sobol|random (render::sampler_name is the flag's word).
void add_sampler_flag(CLI::App* cmd, render::Sampler& sampler) {
    cmd->add_option_function<std::string>(
           "--sampler",
           [&sampler](const std::string& v) {
               sampler = v == "random" ? render::Sampler::random : render::Sampler::sobol;
           },
           "the paths' random numbers: Owen-scrambled Sobol points per pixel (sobol, default: less "
           "noise at the same spp) or independent numbers (random)")
        ->check(CLI::IsMember({"sobol", "random"}));
}

} // namespace

void add_render_option_flags(CLI::App* cmd, render::RenderOptions& o) {
    cmd->add_option("--width", o.width, "image width in pixels")->check(CLI::Range(1u, 16384u));
    cmd->add_option("--height", o.height, "image height in pixels")->check(CLI::Range(1u, 16384u));
    cmd->add_option("--spp", o.spp, "samples per pixel")->check(CLI::Range(1u, 1u << 20));
    cmd->add_option("--max-depth", o.max_depth, "maximum path segments (1 = direct visibility)")
        ->check(CLI::Range(1u, 256u));
    cmd->add_option("--seed", o.seed, "random seed");
    cmd->add_option("--neural-roughness", o.neural.roughness, "override the roughness of neural surfaces [0,1] (default: each asset's glTF material)");
    cmd->add_option("--neural-metallic", o.neural.metallic, "override the metallic of neural surfaces [0,1] (default: each asset's glTF material)");
    cmd->add_option("--neural-max-leaves", o.neural.max_rounds,
                    "neural leaves queried per ray at most (then the closest hit so far is kept)");
    cmd->add_option(
           "--neural-max-leaves-secondary", o.neural.max_rounds_secondary,
           "neural leaves queried per ray at most by rays after the first hit (and by shadow rays, unless "
           "--neural-max-leaves-shadow), at most --neural-max-leaves (a truncated ray keeps its closest hit "
           "so far); 0: --neural-max-leaves; default 2")
        ->check(CLI::Range(0u, 256u));
    cmd->add_option("--neural-max-leaves-shadow", o.neural.max_rounds_shadow,
                    "neural leaves queried per shadow ray at most, at most --neural-max-leaves (a truncated "
                    "shadow ray: --neural-truncated-shadows); 0 (default): --neural-max-leaves-secondary")
        ->check(CLI::Range(0u, 256u));
    cmd->add_option_function<std::string>(
           "--neural-truncated-shadows",
           [&o](const std::string& v) { o.neural.truncated_shadows_occlusion = truncated_shadows_occlusion(v); },
           "a shadow ray truncated by its leaf budget (a leaf left in front of its end; with occupancy "
           "masks, one whose cells along the ray are occupied): occluded by that leaf (block, default), "
           "unoccluded (pass), or occluded with probability P in [0, 1] (a hash of the ray)")
        ->check([](const std::string& v) -> std::string {
            return truncated_shadows_occlusion(v) >= 0.0f ? "" : "must be block, pass or a probability in [0, 1]";
        });
    cmd->add_option("--neural-batched-rounds", o.neural.batched_rounds,
                    "leaf rounds through the batched query pass before the per-ray tail pass");
    cmd->add_option("--neural-leaves-per-round", o.neural.leaves_per_round,
                    "neural leaves a ray after the first hit or a shadow ray queues per traversal round "
                    "(speculative ones included; same image); default 2");
    cmd->add_option("--neural-leaves-per-round-camera", o.neural.leaves_per_round_camera,
                    "neural leaves a camera ray queues per traversal round (same image); default 1");
    cmd->add_option_function<std::string>(
           "--neural-occupancy", [&o](const std::string& v) { o.neural.occupancy = v == "on"; },
           "skip neural leaves whose ray segment crosses only empty cells of the model's occupancy masks "
           "(on, default; models without masks query every leaf) or query every leaf (off)")
        ->check(CLI::IsMember({"on", "off"}));
    cmd->add_option_function<std::string>(
           "--neural-materials",
           [&o](const std::string& v) {
               o.neural.materials = v == "mix"    ? render::NeuralMaterials::mix
                                    : v == "fit"  ? render::NeuralMaterials::fit
                                    : v == "node" ? render::NeuralMaterials::node
                                                  : render::NeuralMaterials::asset;
           },
           "metallic and roughness of a neural hit, from the triangles of the N-BVH node that answered it: "
           "a linear function of the hit's predicted albedo plus a random two-point spread of what it leaves "
           "(mix, default), the function alone (fit; models before format version 5 use node), their mean "
           "(node; before version 4: asset), or the whole asset's mean (asset)")
        ->check(CLI::IsMember({"mix", "fit", "node", "asset"}));
    cmd->add_option_function<std::string>(
           "--neural-backface-escape", [&o](const std::string& v) { o.neural.backface_escape = v == "on"; },
           "a ray leaving a neural hit seen from behind skips back-facing neural hits, so that it leaves the "
           "asset (on, default) or bounces on inside it (off: the paper's and the official code's behaviour)")
        ->check(CLI::IsMember({"on", "off"}));
    cmd->add_option_function<std::string>(
           "--neural-query", [&o](const std::string& v) { o.neural.split_query = v == "split"; },
           "the neural query pass as a gather pass then an MLP pass (split, default where the fp32 "
           "cooperative-matrix MLP runs: the gathers run at higher occupancy) or as one fused kernel "
           "(fused); "
           "same image")
        ->check(CLI::IsMember({"split", "fused"}));
    cmd->add_option(
           "--neural-split-min-pairs", o.neural.split_min_pairs,
           "rounds of fewer queued (ray, leaf) pairs than this take the fused query pass instead of the "
           "split one (its two dispatches cost more than they save on a small round; same image); "
           "0: every round splits (default " +
               std::to_string(render::DEFAULT_SPLIT_MIN_PAIRS) + ")")
        ->check(CLI::Range(0u, 1u << 30));
    cmd->add_option_function<std::string>(
           "--sort-rays", [&o](const std::string& v) { o.sort_rays = v == "on"; },
           "trace secondary and shadow rays grouped by direction and origin (on, default) "
           "or in queue order (off); same image")
        ->check(CLI::IsMember({"on", "off"}));
    add_sampler_flag(cmd, o.sampler);
    cmd->add_option("--wave-pixels", o.max_wave_pixels,
                    "paths traced per wave (rays per queue; several samples of each pixel while they fit in 32M paths, "
                    "up to 32; also bounded by the device's buffer, memory and dispatch limits)")
        ->check(CLI::Range(64u, 1u << 26));
}

Environment choose_environment(const Scene& scene, const std::string& env_path) {
    const render::SceneFeatures f = render::derive_features(scene, Environment{});
    if (env_path == ENV_NONE) {
        if (!f.has_lights())
            log_warn("render: --env none and the scene has no emitter or light: the image is black");
        return Environment{};
    }
    if (!env_path.empty()) return load_environment(env_path);
    if (!scene.environment.empty()) return scene.environment;
    // As glTF viewers do: glTF carries no environment, so every scene gets the default one, its own
    // emitters and lights added (a scene lit only by weak emissive triangles would otherwise be black).
    log_info("render: lighting with the default sky%s (--env FILE to change, --env none for the scene's own "
             "lights only)", f.has_lights() ? " and the scene's emitters and lights" : "");
    return default_sky();
}

Camera choose_camera(const Scene& scene, const std::string& camera_arg, const render::RenderOptions& o) {
    const float aspect = float(o.width) / float(std::max(1u, o.height));
    if (!camera_arg.empty()) return parse_camera(camera_arg);
    return scene.has_camera ? scene.camera : auto_frame(scene, aspect);
}

ModelScene load_model_scene(const std::string& scene_arg, const std::string& model_path,
                            const std::string& env_path, std::optional<float> env_rotation_deg,
                            const std::string& camera_arg, const render::RenderOptions& o,
                            uint32_t subdivide) {
    ModelScene m;
    m.model = load_model(model_path);
    SceneLoadOptions lo;
    lo.subdivide = subdivide;
    m.scene = load_scene_for_model(scene_arg, lo, &m.model, model_path);
    m.env = choose_environment(m.scene, env_path);
    if (env_rotation_deg) m.env.rotation = *env_rotation_deg * 3.14159265358979f / 180.0f;
    m.camera = choose_camera(m.scene, camera_arg, o);
    return m;
}

void add_subdivide_option(CLI::App* cmd, uint32_t& levels) {
    cmd->add_option(
           "--subdivide", levels,
           "split every triangle into 4, L times: the same surface in 4^L times the triangles (a dense "
           "asset's classical cost); a model is used with the --subdivide it was trained with")
        ->check(CLI::Range(0u, MAX_SUBDIVISION_LEVELS));
}

std::optional<float> parse_exposure(const std::string& text) {
    if (text == "auto") return std::nullopt;
    try {
        size_t used = 0;
        const float v = std::stof(text, &used);
        if (used == text.size() && std::isfinite(v) && std::fabs(v) <= 24.0f) return v;
    } catch (const std::exception&) {
    }
    throw Error(strfmt("--exposure '%s': expected 'auto' or a number of stops in [-24, 24]", text.c_str()));
}

int32_t parse_secondary_lod(const std::string& text) {
    if (text == "coarsest") return render::SECONDARY_LOD_COARSEST;
    if (text == "same") return render::SECONDARY_LOD_SAME;
    if (text.size() == 1 && text[0] >= '0' && text[0] <= '7') return text[0] - '0';
    throw Error(strfmt("--secondary-lod '%s': expected 'coarsest', 'same' or a level of detail 0..7", text.c_str()));
}

BackendChoice parse_backend(const std::string& s) {
    if (s == "cpu") return BackendChoice::cpu;
    if (s == "cuda") return BackendChoice::cuda;
    if (s == "auto") return BackendChoice::automatic;
    throw Error(strfmt("--backend must be cpu, cuda or auto (got '%s')", s.c_str()));
}

} // namespace nbvh::app
