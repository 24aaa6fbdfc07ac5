#include "app/scene_arg.h"

#include "assets/default_scene.h"
#include "engine/core/log.h"
#include "engine/neural/asset_table.h"
#include "engine/scene/subdivide.h"

namespace nbvh::app {

Scene load_scene_arg(const std::string& arg, const SceneLoadOptions& options) {
    if (arg == "default") {
        Scene scene = assets::make_default_scene();
        subdivide_scene(scene, options.subdivide);
        if (!options.neural_glob.empty()) mark_neural_by_glob(scene, options.neural_glob);
        return scene;
    }
    return load_gltf(arg, options);
}

Scene load_scene_for_model(const std::string& arg, const SceneLoadOptions& options, const NeuralModel* model,
                           const std::string& model_path) {
    Scene scene = load_scene_arg(arg, options);
    if (!model) return scene;
    if (!options.neural_glob.empty())
        log_warn("--neural '%s' is ignored: the model's asset table decides which instances are neural",
                 options.neural_glob.c_str());
    bind_model_to_scene(scene, *model, model_path);
    return scene;
}

} // namespace nbvh::app
