// The scene a training run learns (nbvh train, nbvh study): loaded, its neural instances marked (the
// nodes of a "*_neural" glTF scene, or --neural GLOB), neural meshes of several materials split into one
// asset per material (engine/neural/asset_table.h), and the assets kept by --asset GLOB.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "engine/scene/scene.h"

namespace nbvh::app {

struct TrainingScene {
    Scene scene;
    uint64_t source_hash = 0;     // fnv1a64 of the file; of the geometry for the built-in scene
    std::vector<uint32_t> meshes; // the neural meshes (assets) to learn, indices into scene.meshes
};

// `subdivide`: flat midpoint subdivision levels of every mesh (engine/scene/subdivide.h), before the
// assets are cut; a render of the model must load the scene with the same levels.
// Throws nbvh::Error for a --neural glob that matches no node, an --asset glob that matches no asset, or a
// scene without a neural asset.
TrainingScene load_training_scene(const std::string& scene_arg, const std::string& neural_glob,
                                  const std::string& asset_glob, uint32_t subdivide = 0);

} // namespace nbvh::app
