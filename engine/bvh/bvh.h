// The canonical CPU BVH: binary, SAH-built, with parents and node bounds kept, because it is also
// the "base BVH" the N-BVH cut is taken from (paper §3.2). Converted to GpuBvhNode for shaders.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "engine/scene/scene.h" // Aabb
#include "shaders/shared/bvh_node.h"

namespace nbvh {

inline constexpr uint32_t BVH_INVALID = 0xFFFFFFFFu;

struct BvhNode {
    Aabb bounds;
    uint32_t left = BVH_INVALID, right = BVH_INVALID; // children (interior nodes)
    uint32_t first = 0, count = 0;                     // range in Bvh::prim_indices (leaves: count > 0)
    uint32_t parent = BVH_INVALID;
    uint32_t depth = 0;
    bool is_leaf() const { return count > 0; }
};

struct Bvh {
    std::vector<BvhNode> nodes;          // nodes[0] is the root; empty for an empty primitive set
    std::vector<uint32_t> prim_indices;  // leaf ranges index into this; values are input primitive ids
    bool empty() const { return nodes.empty(); }
    uint32_t max_depth() const;
};

struct BvhBuildOptions {
    uint32_t max_leaf_size = 4;    // <= NB_LEAF_MAX_COUNT
    uint32_t bin_count = 16;
    float traversal_cost = 1.0f;   // SAH cost of visiting a node relative to one primitive test
};

// SAH build over primitive bounds (binned). Primitives with empty or non-finite bounds are left out.
Bvh build_bvh(std::span<const Aabb> prim_bounds, const BvhBuildOptions& options = {});

// Two-child GPU layout; leaf references index `prim_indices` order (callers reorder their primitive
// arrays by prim_indices so that a leaf's items are contiguous).
std::vector<GpuBvhNode> to_gpu_layout(const Bvh& bvh);

} // namespace nbvh
