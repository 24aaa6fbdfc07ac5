// Training rays (paper §3 "Neural ray query", §4.2 "Ray distribution"; official notes §6): origins
// uniform in the 1.5x inflated asset box, directions uniform on the sphere, and the first leaf of the
// current N-BVH cut that each ray meets. Everything is in the asset's object space.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "engine/bvh/bvh.h"
#include "engine/scene/scene.h"
#include "trainer/pcg32.h"

namespace nbvh {

// Ray/box slab test with mint = -inf (notes §1: t_entry may be negative). Axis-parallel rays are
// handled without 0*inf (an origin exactly on a face of a parallel slab counts as inside).
// Returns false when the line misses the box or the box is empty/non-finite.
bool clip_line_to_box(const glm::vec3& origin, const glm::vec3& dir, const Aabb& box, float& t_entry, float& t_exit);

// centre +- extent*(1+d)/2 (notes §1 "dilation").
Aabb dilate_box(const Aabb& box, float dilation);

// Uniform direction on the unit sphere (phi = 2 pi u1, cos theta = 2 u2 - 1).
glm::vec3 uniform_sphere_direction(float u1, float u2);

// The cut being trained: leaves as base-BVH node ids plus the reverse map base node -> leaf slot.
struct TrainingCut {
    std::vector<uint32_t> leaves;            // base-BVH node ids
    std::vector<int32_t> leaf_of_base_node;  // size = base nodes, -1 where the node is not a cut leaf
    std::vector<float> keep_probability;     // per leaf slot, survival roulette (paper §4.2)

    void assign(std::span<const uint32_t> leaf_nodes, size_t base_node_count);
    size_t size() const { return leaves.size(); }
};

// What a ray meets first in a cut: the leaf with the smallest dilated-box entry among leaves whose
// box segment is not entirely behind the origin (t_exit > min_exit). -1 when nothing is hit.
struct FirstLeaf {
    int32_t leaf = -1;     // slot in TrainingCut::leaves
    float t_entry = 0.0f;  // may be negative (origin inside the leaf box)
    float t_exit = 0.0f;
};

// Nearest-first descent of the base BVH from `root` (a part's subtree, training_asset.h), stopping at cut
// leaves. `node_boxes` are the (regularised) boxes per base node, `dilation` is relative to each box's extent.
FirstLeaf first_leaf_of_cut(const Bvh& base, std::span<const Aabb> node_boxes, const TrainingCut& cut,
                            const glm::vec3& origin, const glm::vec3& dir, float dilation, float min_exit,
                            uint32_t root = 0);

} // namespace nbvh
