#include "app/viewer/viewer_scene.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <set>

#include "app/render_args.h"
#include "app/scene_arg.h"
#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/neural/asset_table.h"
#include "engine/scene/camera.h"
#include "engine/render/gpu_memory.h"

namespace nbvh::viewer {

bool ViewerScene::has_neural_instances() const {
    return std::any_of(scene.instances.begin(), scene.instances.end(), [](const Instance& i) { return i.neural; });
}

std::unique_ptr<ViewerScene> load_viewer_scene(const std::string& source, const SceneOptions& options,
                                               std::shared_ptr<const NeuralModel> model,
                                               const std::string& model_name, float aspect) {
    auto v = std::make_unique<ViewerScene>();
    v->source = source;
    v->model_name = model ? model_name : std::string();
    v->model = std::move(model);
    SceneLoadOptions lo;
    lo.neural_glob = options.neural_glob;
    lo.subdivide = options.subdivide;
    // With a model its asset table decides which instances are neural (the --neural glob is ignored).
    if (v->model) lo.neural_glob.clear();
    v->scene = app::load_scene_for_model(source, lo, v->model.get(), model_name);
    v->env = app::choose_environment(v->scene, options.env);
    v->home = v->scene.has_camera ? v->scene.camera : auto_frame(v->scene, aspect);
    const auto t0 = std::chrono::steady_clock::now();
    v->accel = build_scene_accel(v->scene);
    v->bvh_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    log_info("view: %s%s%s, BVHs built in %.1f ms", source.c_str(), v->model ? " with " : "",
             v->model_name.c_str(), v->bvh_ms);
    return v;
}

std::unique_ptr<ViewerScene> with_model(const ViewerScene& from, std::shared_ptr<const NeuralModel> model,
                                        const std::string& model_name) {
    NBVH_CHECK(model != nullptr);
    auto v = std::make_unique<ViewerScene>();
    v->source = from.source;
    v->model_name = model_name;
    v->model = std::move(model);
    v->scene = from.scene;
    bind_model_to_scene(v->scene, *v->model, model_name);
    v->env = from.env;
    v->home = from.home;
    const auto t0 = std::chrono::steady_clock::now();
    v->accel = build_scene_accel(v->scene);
    v->bvh_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    log_info("view: %s with %s, BVHs built in %.1f ms", v->source.c_str(), model_name.c_str(), v->bvh_ms);
    return v;
}

bool same_assets(const NeuralModel& a, const NeuralModel& b) {
    if (a.assets.size() != b.assets.size()) return false;
    for (size_t i = 0; i < a.assets.size(); ++i) {
        const ModelAsset &x = a.assets[i], &y = b.assets[i];
        if (x.name != y.name || x.geometry_hash != y.geometry_hash || x.material_hash != y.material_hash)
            return false;
    }
    return true;
}

DropKind classify_drop(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".gltf" || ext == ".glb") return DropKind::scene;
    if (ext == ".nbvh") return DropKind::model;
    throw Error(strfmt("cannot open '%s': expected a .gltf, .glb or .nbvh file", path.c_str()));
}

NeuralMemory neural_memory(const ViewerScene& v, uint32_t lod) {
    NeuralMemory m;
    std::set<uint32_t> meshes;
    for (const Instance& i : v.scene.instances)
        if (i.neural) {
            meshes.insert(i.mesh);
            m.neural_instances++;
        }
    for (uint32_t mesh : meshes)
        if (mesh < v.accel.meshes.size()) m.classical_bytes += render::mesh_gpu_bytes(v.scene.meshes[mesh], v.accel.meshes[mesh]);
    if (!v.model) return m;
    m.assets = uint32_t(v.model->assets.size());
    const render::NeuralGpuBytes b = render::neural_gpu_bytes(*v.model);
    m.model_bytes = b.total();
    m.lod_bytes = b.total_for_lod(lod);
    return m;
}

} // namespace nbvh::viewer
