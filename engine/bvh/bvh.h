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
    uint32_t max_leaf_size = 4;    // clamped to [1, NB_LEAF_MAX_COUNT]
    uint32_t bin_count = 16;       // SAH bins per axis, clamped to [2, 256]
    float traversal_cost = 1.0f;   // SAH cost of visiting a node relative to one primitive test
    // When > 0, node bounds thinner than this on an axis are padded to it after the build (the N-BVH
    // base BVH uses BBOX_REGULARISATION = 1e-4, official notes §1); parents are regrown to contain
    // their padded children. 0 keeps exact bounds (triangle BLAS/TLAS).
    float min_node_extent = 0.0f;
    // Threads that build subtrees at once (0: every core). Any count gives the same Bvh, node for node:
    // each subtree is built as the one-thread build would and placed where it would place it.
    uint32_t threads = 0;
};

// Binned SAH build over primitive bounds. Primitives with empty or non-finite bounds are left out
// (prim_indices then holds fewer ids than the input). Guarantees: every kept primitive is in exactly
// one leaf; leaves hold 1..max_leaf_size primitives; node depth < NB_BVH_MAX_DEPTH (falls back to
// median splits when SAH would go deeper); the two children of a node are adjacent (right = left + 1)
// and stored after their parent. Throws nbvh::Error for more than 2^27 primitives (GPU leaf refs).
Bvh build_bvh(std::span<const Aabb> prim_bounds, const BvhBuildOptions& options = {});

// Pads node bounds thinner than `min_extent` (see BvhBuildOptions::min_node_extent) in place.
void pad_node_bounds(Bvh& bvh, float min_extent);

// One BVH over several parts (the multi-asset training BVH, trainer/training_asset.h): a SAH tree over the
// parts' root boxes whose leaves are the parts' own trees, so every part is one subtree. Part p's
// primitive ids are shifted by prim_offsets[p]; part_roots (when given) receives the node index of each
// part's root. Node invariants of build_bvh hold (children adjacent, after their parent). Throws
// nbvh::Error when a part is empty or the joined tree would be deeper than NB_BVH_MAX_DEPTH.
Bvh join_bvhs(std::span<const Bvh> parts, std::span<const uint32_t> prim_offsets,
              std::vector<uint32_t>* part_roots = nullptr);
// Two-child GPU layout; leaf references index `prim_indices` order (callers reorder their primitive
// arrays by prim_indices so that a leaf's items are contiguous).
std::vector<GpuBvhNode> to_gpu_layout(const Bvh& bvh);

} // namespace nbvh
