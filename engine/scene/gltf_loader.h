// glTF 2.0 (.gltf + .bin/images, or .glb) -> nbvh::Scene, through tinygltf.
//
// What is loaded: the node hierarchy of the main scene (TRS or matrix; the same mesh on several nodes gives
// several Instances of one Mesh), triangle primitives (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN; points and
// lines are skipped with a warning), metallic-roughness materials with KHR_texture_transform,
// KHR_materials_emissive_strength and KHR_materials_transmission, KHR_lights_punctual lights, and the first
// glTF camera.
// The environment is not part of glTF: Scene::environment stays empty (see environment.h).
//
// Bad input (see ../shared/scenes/bad/README.md) gives either an nbvh::Error with one line naming the file and
// the problem (broken JSON/GLB, missing or short buffer, accessor larger than its bufferView, node cycle,
// missing scene, coordinates beyond MAX_COORDINATE), or a scene with the bad parts removed and a warning
// (non-finite or out-of-range-index triangles, zero-area-only meshes, bad normals, undecodable textures).
// Every position and normal in the result is finite; indices are in range.
#pragma once
#include <filesystem>
#include <string>

#include "engine/scene/scene.h"

namespace nbvh {

struct SceneLoadOptions {
    // Nodes whose name matches this glob ('*', '?') become neural instances. Empty: the glTF convention
    // (ARCHITECTURE.md "Which assets are neural"): nodes of a scene named "*_neural" are neural.
    std::string neural_glob;
    // Decode and keep textures. false: geometry-only load (all TextureRefs are -1, no tangents).
    bool keep_textures = true;
    // Throw nbvh::Error "no renderable geometry" instead of returning a scene without triangles.
    bool require_geometry = false;
    // Flat midpoint subdivision levels applied to every mesh after loading (engine/scene/subdivide.h):
    // the same surface in 4^subdivide times the triangles. The built-in default scene takes it from the
    // app's loaders (app/scene_arg.h).
    uint32_t subdivide = 0;
};

Scene load_gltf(const std::filesystem::path& path, const SceneLoadOptions& options = {});

// How the neural flag was decided, for logs: marks instances and returns e.g. "glob 'Pawn*'" or
// "scene 'scene_neural'" or "none". Called by load_gltf; exposed for re-marking a loaded scene.
std::string mark_neural_by_glob(Scene& scene, const std::string& glob);

} // namespace nbvh
