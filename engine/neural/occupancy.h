// Occupancy masks of the N-BVH nodes (shaders/shared/neural_occupancy.h: what they are, how the GPU
// traversal walks them; a departure from the paper, see there). Built once at the end of training from
// the asset's triangles and stored in the model file (section OCCU, MODEL_FORMAT.md).
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "engine/neural/nbvh_tree.h"
#include "engine/scene/scene.h"
#include "shaders/shared/neural_occupancy.h"

namespace nbvh {

// Whether a node is a leaf at some LoD (the nodes the traversal can query, so the ones with a mask).
inline bool occupancy_node_used(const NbvhNode& n) { return !n.has_children() || n.lod != NBVH_LOD_NONE; }

// NB_OCC_WORDS words per node, node-major. A used node's bit is set when a triangle of `mesh` (the
// space of the node boxes: the training asset's atlas mesh) touches the cell grown by
// NB_OCC_MARK_MARGIN of a cell on every side (a conservative triangle-box test in double precision);
// unused nodes get every bit (never read). `threads` 0 = hardware concurrency.
std::vector<uint32_t> build_occupancy(std::span<const NbvhNode> nodes, const Mesh& mesh, uint32_t threads = 0);

// The host twin of the GPU test (lib/neural_traverse.glsl): does the segment [t0, t1] of the ray cross
// an occupied cell of the node whose mask starts at `words`? True where the walk is not exact.
bool occupancy_segment_occupied(const uint32_t* words, const glm::vec3& org, const glm::vec3& dir, const Aabb& box,
                                float t0, float t1);

// Set bits / all bits over the nodes that are leaves of LoD `lod` (for logs and `nbvh info`).
double occupancy_fraction(const NbvhTree& tree, std::span<const uint32_t> words, uint32_t lod);

// Triangle vs axis-aligned box overlap (separating axes, Akenine-Moller 2001), double precision;
// touching counts as overlap. Exposed for tests.
bool triangle_box_overlap(const glm::dvec3& box_center, const glm::dvec3& box_half, const glm::dvec3& a,
                          const glm::dvec3& b, const glm::dvec3& c);

} // namespace nbvh
