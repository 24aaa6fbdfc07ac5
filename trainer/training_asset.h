// One neural asset prepared for training: its mesh in its own object space, the classical BVH over
// its triangles (the "base BVH" the N-BVH cut is taken from, paper §3.2, and the ground-truth tracer,
// notes §6.7), the regularised node boxes and the encoding/sampling boxes.
//
// Scale independence: the official code pads thin boxes and picks epsilons in absolute world units
// tuned for ~0.5-unit scenes (notes §14). Here every such constant is relative to the asset's size
// (and to the float spacing at its distance from the origin), so assets at 1e-3 or 1e5 scale, flat
// ones and ones far from the origin train the same way.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "engine/bvh/bvh.h"
#include "engine/bvh/mesh_bvh.h"
#include "engine/scene/scene.h"
#include "shaders/shared/neural_query.h"

namespace nbvh {

struct TrainingAsset {
    const Scene* scene = nullptr;       // materials and textures
    uint32_t mesh_index = 0;
    const Mesh* mesh = nullptr;
    std::string name;
    MeshBvh mesh_bvh;                   // SAH, leaves of <= 2 triangles (official max leaf size),
                                        // node bounds padded to at least `min_extent` per axis
    const Bvh& bvh() const { return mesh_bvh.bvh; } // the base BVH of the N-BVH cut
    std::vector<Aabb> node_boxes;       // bvh().nodes[i].bounds, contiguous for traversal
    Aabb bounds;                        // node_boxes[0]: the asset box
    GpuEncodingBox encoding;            // maps points to [0,1]^3 for the hash grid (neural_query.h)
    Aabb sampling_box;                  // bounds scaled 1.5x about the centre (paper §3)
    float min_extent = 0.0f;            // thin-axis padding (object units)
    float min_exit = 0.0f;              // a leaf segment must end this far in front of the origin
    uint32_t triangle_count() const { return mesh ? mesh->triangle_count() : 0u; }
};

// Which mesh of a scene is trained: the neural instance's mesh with the most triangles (one neural
// mesh per model in this version; instances of it share the model). Throws nbvh::Error when the
// scene has no neural instance or the chosen mesh has no valid triangles.
uint32_t pick_neural_mesh(const Scene& scene);

// Builds the BVH and boxes. `scene` must outlive the result.
TrainingAsset make_training_asset(const Scene& scene, uint32_t mesh_index);

} // namespace nbvh
