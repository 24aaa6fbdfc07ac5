// Render options shared by the subcommands that render (nbvh render, nbvh bench): the CLI flags that
// fill render::RenderOptions, and the environment and camera a render of a scene uses when none is given.
#pragma once
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "engine/neural/model_file.h"
#include "engine/render/wavefront.h"
#include "engine/scene/scene.h"
#include "trainer/trainer.h"

namespace nbvh::app {

// Adds --width --height --spp --max-depth --seed --wave-pixels --sampler and the neural material/round flags
// (--neural-roughness --neural-metallic --neural-max-leaves --neural-batched-rounds
// --neural-leaves-per-round), writing into `o`
// (which must outlive the parse).
void add_render_option_flags(CLI::App* cmd, render::RenderOptions& o);

// The environment to light with: `env_path` (--env FILE), none for --env none (only the scene's emitters
// and lights: black background), else the scene's, else the default sky, added to the scene's own
// emitters and lights (issue 12: every scene is lit as viewers light it).
Environment choose_environment(const Scene& scene, const std::string& env_path);
inline constexpr const char* ENV_NONE = "none";

// The view: `camera_arg` (--camera ex,ey,ez,tx,ty,tz,fov), else the scene's, else auto-framed for the
// image aspect of `o`.
Camera choose_camera(const Scene& scene, const std::string& camera_arg, const render::RenderOptions& o);

// What the subcommands that compare a model with its triangles (nbvh bench, nbvh converge) render: the
// model, the scene bound to it (its asset table decides which instances are neural; scene_arg.h), the
// environment (choose_environment, turned by `env_rotation_deg`) and the camera (choose_camera for `o`).
// Keep it where it is made: render options point at `model`.
struct ModelScene {
    NeuralModel model;
    Scene scene;
    Environment env;
    Camera camera;
};
ModelScene load_model_scene(const std::string& scene_arg, const std::string& model_path,
                            const std::string& env_path, std::optional<float> env_rotation_deg,
                            const std::string& camera_arg, const render::RenderOptions& o,
                            uint32_t subdivide = 0);

// --subdivide L (engine/scene/subdivide.h) for every command that loads a scene: the same surface in 4^L
// times the triangles; a model is used with the --subdivide it was trained with.
void add_subdivide_option(CLI::App* cmd, uint32_t& levels);

// --exposure: "auto" (nullopt) or a number of stops in [-24, 24]; throws nbvh::Error otherwise.
std::optional<float> parse_exposure(const std::string& text);
// --secondary-lod: "coarsest" (render::SECONDARY_LOD_COARSEST), "same" (as --lod) or a LoD index 0..7;
// throws nbvh::Error otherwise.
int32_t parse_secondary_lod(const std::string& text);
// --backend: cpu, cuda or auto; throws nbvh::Error otherwise.
BackendChoice parse_backend(const std::string& text);

} // namespace nbvh::app
