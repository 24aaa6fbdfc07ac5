// The SCENE argument shared by the subcommands: "default" is the built-in demo scene
// (assets/default_scene.h), anything else a glTF file.
#pragma once
#include <string>

#include "engine/scene/gltf_loader.h"
#include "engine/scene/scene.h"

namespace nbvh::app {

Scene load_scene_arg(const std::string& arg, const SceneLoadOptions& options = {});

} // namespace nbvh::app
