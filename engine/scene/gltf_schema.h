// A few JSON-schema checks that tinygltf does not make (it silently drops properties of the wrong type,
// e.g. bad/assimp/wrongTypes: `primitives` not an array, `normalTexture.scale` a string). Internal to the
// glTF loader; runs on the raw JSON after tinygltf has parsed the file successfully.
#pragma once
#include <filesystem>

namespace nbvh::gltf {

// Throws nbvh::Error for structural mistakes that would change the geometry (meshes, primitives, nodes);
// warns for material properties of the wrong type (they are ignored, i.e. take their defaults).
void check_schema(const std::filesystem::path& path);

} // namespace nbvh::gltf
