#include "app/training_scene.h"

#include "assets/default_scene.h"
#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/neural/asset_table.h"
#include "engine/neural/model_file.h"
#include "engine/scene/gltf_loader.h"
#include "engine/scene/scene_stats.h"
#include "engine/scene/subdivide.h"
#include "trainer/training_asset.h"

namespace nbvh::app {

TrainingScene load_training_scene(const std::string& scene_arg, const std::string& neural_glob,
                                  const std::string& asset_glob, uint32_t subdivide) {
    TrainingScene t;
    Scene& scene = t.scene;
    if (scene_arg == "default") {
        scene = assets::make_default_scene();
        subdivide_scene(scene, subdivide);
        if (!neural_glob.empty()) mark_neural_by_glob(scene, neural_glob);
        // The built-in scene has no file to hash: hash its geometry, so the model still names its source.
        t.source_hash = FNV1A64_OFFSET;
        for (const Mesh& m : scene.meshes) {
            t.source_hash =
                fnv1a64(m.positions.data(), m.positions.size() * sizeof(m.positions[0]), t.source_hash);
            t.source_hash = fnv1a64(m.indices.data(), m.indices.size() * sizeof(m.indices[0]), t.source_hash);
        }
    } else {
        SceneLoadOptions lo;
        lo.neural_glob = neural_glob;
        lo.require_geometry = true;
        lo.subdivide = subdivide;
        scene = load_gltf(scene_arg, lo);
        t.source_hash = fnv1a64_file(scene_arg);
    }
    if (!neural_glob.empty()) {
        bool matched = false;
        for (const Instance& inst : scene.instances) matched = matched || inst.neural;
        if (!matched)
            throw Error(
                strfmt("--neural '%s' matches no node of '%s'", neural_glob.c_str(), scene_arg.c_str()));
    }
    split_neural_meshes(scene);
    for (uint32_t m : neural_meshes(scene))
        if (asset_glob.empty() || glob_match(asset_glob, scene.meshes[m].name)) t.meshes.push_back(m);
    if (t.meshes.empty()) {
        if (!asset_glob.empty())
            throw Error(strfmt("--asset '%s' matches no neural asset", asset_glob.c_str()));
        pick_neural_mesh(scene); // throws the "no neural asset" message
    }
    return t;
}

} // namespace nbvh::app
