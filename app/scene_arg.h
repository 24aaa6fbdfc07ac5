// The SCENE argument shared by the subcommands: "default" is the built-in demo scene
// (assets/default_scene.h), anything else a glTF file.
#pragma once
#include <string>

#include "engine/neural/model_file.h"
#include "engine/scene/gltf_loader.h"
#include "engine/scene/scene.h"

namespace nbvh::app {

Scene load_scene_arg(const std::string& arg, const SceneLoadOptions& options = {});

// The scene for a render with a model (engine/neural/asset_table.h bind_model_to_scene): the model's
// asset table decides which instances are neural (a --neural glob is then ignored, with a warning),
// meshes are split by material as at training time, and a model that does not match is refused with
// one line naming the asset. Without a model, as load_scene_arg.
Scene load_scene_for_model(const std::string& arg, const SceneLoadOptions& options, const NeuralModel* model,
                           const std::string& model_path);

} // namespace nbvh::app
