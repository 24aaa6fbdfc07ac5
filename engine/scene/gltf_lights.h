// KHR_lights_punctual: the file's point, spot and directional lights, placed by the nodes that reference
// them (internal to the loader). Light properties are not scaled by the node (extension spec): only the
// position and the direction (the node's -z axis, normalised) are transformed.
#pragma once
#include <optional>
#include <string>

#include <glm/glm.hpp>

#include "engine/scene/scene.h"

namespace tinygltf {
class Model;
class Node;
} // namespace tinygltf

namespace nbvh::gltf {

// The light node `node` references through its KHR_lights_punctual extension, in world space (`world`:
// the node's world transform), or nullopt when it references none. Invalid lights (unknown type, bad
// index, negative or non-finite intensity, a degenerate transform) are skipped with a warning naming
// them; out-of-range cone angles and ranges are clamped or ignored with a warning, as the spec bounds them.
std::optional<PunctualLight> node_light(const tinygltf::Model& model, const tinygltf::Node& node,
                                        int node_index, const glm::dmat4& world, const std::string& file);

} // namespace nbvh::gltf
