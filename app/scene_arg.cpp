#include "app/scene_arg.h"

#include "assets/default_scene.h"
#include "engine/core/log.h"

namespace nbvh::app {

Scene load_scene_arg(const std::string& arg, const SceneLoadOptions& options) {
    if (arg == "default") {
        Scene scene = assets::make_default_scene();
        if (!options.neural_glob.empty()) mark_neural_by_glob(scene, options.neural_glob);
        return scene;
    }
    return load_gltf(arg, options);
}

} // namespace nbvh::app
