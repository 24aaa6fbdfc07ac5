// What the viewer shows, by lifetime: the scene with its BVHs, lighting and home camera, and the model
// that answers its neural instances (none: classical). Replaced as a whole when a file is dropped on the
// window or live training swaps a model in; renderers hold pointers into it, so they go first.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "engine/bvh/scene_accel.h"
#include "engine/neural/model_file.h"
#include "engine/scene/scene.h"

namespace nbvh::viewer {

struct ViewerScene {
    std::string source;                       // "default" or the glTF path, as given
    std::string model_name;                   // model path ("" without a model)
    std::shared_ptr<const NeuralModel> model; // answers the neural instances (hybrid renders)
    // The training loss of each model node (live training, live_training.h; NaN: none), else null.
    std::shared_ptr<const std::vector<float>> node_loss;
    Scene scene;                              // split by material and bound to the model when there is one
    SceneAccel accel;
    Environment env;
    Camera home;
    double bvh_ms = 0.0;                      // BVH build time (CPU)

    std::vector<uint32_t> lod_node_counts() const {
        return model ? model->lod_node_counts : std::vector<uint32_t>{};
    }
    bool has_neural_instances() const;
};

// How the scene is chosen and lit (the command line's options, kept for dropped files).
struct SceneOptions {
    std::string neural_glob; // --neural: nodes whose name matches are neural (without a model)
    std::string env;         // --env FILE | none | "" (app/render_args.h choose_environment)
    uint32_t subdivide = 0;  // --subdivide L: every mesh split L times (a model needs its training's L)
};

// Loads `source` ("default" or glTF), binds `model` to it when given (engine/neural/asset_table.h:
// a model that does not match is refused naming the asset), builds the BVHs. `aspect` frames the home
// camera of a scene without one. Throws nbvh::Error with the CLI's one-line messages.
std::unique_ptr<ViewerScene> load_viewer_scene(const std::string& source, const SceneOptions& options,
                                               std::shared_ptr<const NeuralModel> model,
                                               const std::string& model_name, float aspect);

// A copy of `from` answered by `model` (a dropped .nbvh, or a live-training snapshot): the scene is
// copied, bound to the model and its BVHs rebuilt; lighting and home camera are kept. Throws
// nbvh::Error when the model does not match the scene.
std::unique_ptr<ViewerScene> with_model(const ViewerScene& from, std::shared_ptr<const NeuralModel> model,
                                        const std::string& model_name);
// Whether two models answer the same assets (names and fingerprints), so one can replace the other
// in a view without binding the scene again (live-training snapshots).
bool same_assets(const NeuralModel& a, const NeuralModel& b);

// What a dropped file is, by its extension (case-insensitive).
enum class DropKind { scene, model };
// Throws nbvh::Error "cannot open 'PATH': expected a .gltf, .glb or .nbvh file" for anything else.
DropKind classify_drop(const std::string& path);

// Memory of the neural part against the classical meshes it replaces, for the stats panel, counted as
// the renderer uploads them (engine/render/gpu_memory.h, as nbvh bench and the results tables).
struct NeuralMemory {
    uint64_t model_bytes = 0;     // every resident buffer of the model (all LoDs)
    uint64_t lod_bytes = 0;       // a model that keeps only the cut of the LoD rendered
    uint64_t classical_bytes = 0; // the unique neural meshes + their BLAS, each mesh once
    uint32_t assets = 0, neural_instances = 0;
};
NeuralMemory neural_memory(const ViewerScene& view, uint32_t lod);

} // namespace nbvh::viewer
