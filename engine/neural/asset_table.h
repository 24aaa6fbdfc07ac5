// The scene side of a model's asset table (ARCHITECTURE.md "Which assets are neural"): a neural asset
// is a unique (mesh, material) of the scene; instances share it. Training and rendering both cut the
// neural meshes of several materials into one mesh per material first (split_neural_meshes), so an
// asset is exactly one scene mesh; fingerprints tie a model to the geometry and material it learned.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "engine/neural/model_file.h"
#include "engine/scene/scene.h"

namespace nbvh {

// Cuts every mesh used by a neural instance whose triangles use several materials into one mesh per
// material (named "MESH/MATERIAL", Mesh::split_from = MESH) and replaces each neural instance of it by
// one instance per part (same node name and transform). Classical instances keep the original mesh.
// Returns how many meshes were cut.
uint32_t split_neural_meshes(Scene& scene);

// FNV-1a 64 of the positions and indices (what the N-BVH learned).
uint64_t geometry_fingerprint(const Mesh& mesh);
// FNV-1a 64 of what the learned albedo depends on: base colour factor and texture (texels, uv set,
// transform) and the alpha mode. 0 for an out-of-range material.
uint64_t material_fingerprint(const Scene& scene, uint32_t material);

// The table entry of scene mesh `mesh` (one material after split_neural_meshes): names, node paths of
// its neural instances, fingerprints. Root, triangles and placement are the trainer's.
ModelAsset describe_asset(const Scene& scene, uint32_t mesh);

// Metallic and roughness of a neural asset's hits: a neural hit has no uv, so the material's factors
// are multiplied by the metallic-roughness texture averaged over the mesh's surface (area-weighted,
// sampled at 4 points per triangle). Without a texture: the factors. (The paper shades neural hits with
// global constants; LSNIF predicts material parameters; the albedo here is learned, these are not.)
// Transmission: the material's factor (a transmissive asset is seen from inside: no back-face escape).
// Per N-BVH node instead: node_materials.h.
struct AssetShading {
    float metallic = 0.0f, roughness = 1.0f, transmission = 0.0f;
};
AssetShading asset_shading(const Scene& scene, uint32_t mesh);

// The albedo a network learns at a surface point (trainer/ground_truth.cpp): linear base colour, factor x
// texture (sRGB decoded) at `uv` when `has_uv`, clamped to [0, 1]; 0.9 without a material (official
// default, notes §6.7) or when not finite.
glm::vec3 learned_albedo(const Scene& scene, const Material* material, glm::vec2 uv, bool has_uv);

// One triangle of `mesh` (index `t`) seen at 4 fixed points (barycentric (1/3,1/3,1/3) and the three
// (2/3,1/6,1/6) permutations): the learned albedo and the metallic-roughness texture's blue (metallic)
// and green (roughness) channels, 1 without a texture (the factors are not applied); `with_albedo` false
// skips the albedo (left 0: the asset means need none). Returns the triangle's area: 0, and `points`
// untouched, for a degenerate triangle or out-of-range indices.
struct MaterialPoint {
    glm::vec3 albedo{0.0f};
    float metallic = 1.0f, roughness = 1.0f;
};
inline constexpr uint32_t MATERIAL_POINTS = 4;
double triangle_material_points(const Scene& scene, const Mesh& mesh, const Material& material, uint32_t t,
                                MaterialPoint points[MATERIAL_POINTS], bool with_albedo = true);

// Binds a model to a scene: the model's assets decide which instances are neural (every instance of a
// glTF mesh the model has an asset for), meshes are split by material, and every neural mesh must
// match its asset (name, geometry and material fingerprints). Returns, per scene mesh (after the
// split), the index of its asset or -1. Throws nbvh::Error with one line naming the first asset that
// does not match (or is missing), prefixed by `model_name`.
std::vector<int32_t> bind_model_to_scene(Scene& scene, const NeuralModel& model, const std::string& model_name);

} // namespace nbvh
