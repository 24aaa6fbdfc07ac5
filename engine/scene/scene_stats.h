// Small queries over a loaded Scene for logs, tests and the --neural option.
#pragma once
#include <cstdint>
#include <string>

#include "engine/scene/scene.h"

namespace nbvh {

struct SceneStats {
    uint64_t meshes = 0, instances = 0, neural_instances = 0;
    uint64_t triangles = 0;           // distinct: each Mesh counted once
    uint64_t instanced_triangles = 0; // as rendered: sum over instances
    uint64_t neural_triangles = 0;    // instanced triangles of neural instances
    uint64_t materials = 0, textures = 0;
};

SceneStats scene_stats(const Scene& scene);

// One line for logs: "flight_helmet.gltf: 6 meshes, 6 instances (0 neural), 94722 triangles (94722 instanced),
// 13 materials, 15 textures, camera: glTF, environment: 1024x512".
std::string describe(const Scene& scene);

// Shell-style glob on node names: '*' = any run of characters (also empty), '?' = one character; the whole
// name must match. Iterative with backtracking to the last '*', O(|pattern| * |name|) worst case.
bool glob_match(const std::string& pattern, const std::string& name);

} // namespace nbvh
