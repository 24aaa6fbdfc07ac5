// One neural asset prepared for training: its mesh in its own object space, the classical BVH over
// its triangles (the "base BVH" the N-BVH cut is taken from, paper §3.2, and the ground-truth tracer,
// notes §6.7), the regularised node boxes and the encoding/sampling boxes.
//
// Scale independence: the official code pads thin boxes and picks epsilons in absolute world units
// tuned for ~0.5-unit scenes (notes §14). Here every such constant is relative to the asset's size
// (and to the float spacing at its distance from the origin), so assets at 1e-3 or 1e5 scale, flat
// ones and ones far from the origin train the same way.
#pragma once
#include <algorithm>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "engine/bvh/bvh.h"
#include "engine/bvh/mesh_bvh.h"
#include "engine/scene/scene.h"
#include "shaders/shared/neural_query.h"

namespace nbvh {

// One neural asset of a multi-asset training run (a unique (mesh, material) of the scene). The assets
// are trained together, by ONE network, each in its own slot of a shared "atlas" space: object space
// scaled uniformly to a unit largest extent and moved to its own cell of a 3D grid of cells, so their
// encodings never overlap in the hash grid. One asset keeps its object space (scale 1, offset 0).
// The renderer composes the same map into the instance's world->object transform.
struct TrainingPart {
    std::string name;         // scene mesh name
    uint32_t mesh_index = 0;  // index into Scene::meshes
    uint32_t root = 0;        // base-BVH node of its subtree (the N-BVH cut never goes above it)
    float scale = 1.0f;       // atlas = object * scale + offset
    glm::vec3 offset{0.0f};
    Aabb bounds;              // atlas space, padded
    Aabb sampling_box;        // bounds scaled 1.5x about the centre (paper §3)
    uint32_t first_triangle = 0, triangle_count = 0; // range in the combined mesh
};

struct TrainingAsset {
    const Scene* scene = nullptr;       // materials and textures
    const Mesh* mesh = nullptr;         // the scene mesh (one part) or the combined atlas mesh (owned_mesh)
    std::shared_ptr<const Mesh> owned_mesh;
    std::string name;
    std::vector<TrainingPart> parts;    // at least one
    MeshBvh mesh_bvh;                   // SAH, leaves of <= 2 triangles (official max leaf size),
                                        // node bounds padded to at least `min_extent` per axis; with
                                        // several parts, their trees joined under a tree of part boxes
    const Bvh& bvh() const { return mesh_bvh.bvh; } // the base BVH of the N-BVH cut
    std::vector<Aabb> node_boxes;       // bvh().nodes[i].bounds, contiguous for traversal
    std::vector<uint8_t> above_parts;   // per base node: 1 = above every part root (split before training)
    Aabb bounds;                        // node_boxes[0]: the asset (atlas) box
    GpuEncodingBox encoding;            // maps points to [0,1]^3 for the hash grid (neural_query.h)
    float min_extent = 0.0f;            // thin-axis padding (object units)
    float min_exit = 0.0f;              // a leaf segment must end this far in front of the origin
    bool alpha_tested = false;          // some triangle's material is glTF MASK or BLEND (ground_truth.h)
    uint32_t triangle_count() const { return mesh ? mesh->triangle_count() : 0u; }
};

// Which mesh of a scene is trained: the neural instance's mesh with the most triangles. Throws
// nbvh::Error when the scene has no neural instance or the chosen mesh has no valid triangles.
uint32_t pick_neural_mesh(const Scene& scene);
// Every mesh of the scene's neural instances, in order of first appearance (each once).
std::vector<uint32_t> neural_meshes(const Scene& scene);

// Builds the BVH and boxes of one mesh or of several (atlas). `scene` must outlive the result.
TrainingAsset make_training_asset(const Scene& scene, uint32_t mesh_index);
TrainingAsset make_training_asset(const Scene& scene, std::span<const uint32_t> meshes);

// The part an uniform draw u in [0,1) picks (every part equally likely: the atlas gives each the same
// size). Shared by the CPU backend, the evaluation and (as the same formula) the CUDA sampler.
inline uint32_t pick_part(const TrainingAsset& asset, float u) {
    const uint32_t n = uint32_t(asset.parts.size());
    return n > 1 ? std::min(uint32_t(u * float(n)), n - 1u) : 0u;
}

} // namespace nbvh
