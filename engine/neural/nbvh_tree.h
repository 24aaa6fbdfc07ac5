// The N-BVH: a cut through the base BVH (paper §3.2), refined by splitting leaves into their base-BVH
// children, with several cuts kept as levels of detail (paper §4.4, official notes §7 and §9).
//
// Nodes are appended, never removed: splitting node n appends its two base-BVH children as the next
// two nodes, so children are adjacent (right = left + 1) and always have larger indices than their
// parent (the model reader relies on both). Node 0 is the root.
//
// Levels of detail: LoD 0 is the finest cut (the final one), LoD lod_count-1 the coarsest, as in the
// official code and the paper ("LoD 0, highest resolution"). Cuts are registered during training from
// the coarsest to the finest; registering stamps every current leaf with that LoD. A node's `lod` is
// the finest LoD at which it is a leaf: walking from the root at LoD L, a node is a leaf when it has
// no children or L >= lod. Cuts are nested, so one node array serves every LoD.
#pragma once
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "engine/bvh/bvh.h"
#include "engine/scene/scene.h"
#include "shaders/shared/bvh_node.h"

namespace nbvh {

inline constexpr uint32_t NBVH_NO_CHILD = 0xFFFFFFFFu;
inline constexpr uint8_t NBVH_LOD_NONE = 0xFF;   // not a leaf at any registered LoD (yet)
inline constexpr uint32_t NBVH_MAX_LODS = 8;      // official NUM_BVH_LODS is 7
inline constexpr uint32_t NBVH_MAX_NODES = NB_LEAF_FIRST_MASK; // leaf refs carry a node index in 27 bits

struct NbvhNode {
    Aabb bounds;                       // the base-BVH node's bounds (object space of the asset), undilated
    uint32_t left = NBVH_NO_CHILD;     // left child (right = left + 1), NBVH_NO_CHILD for a current leaf
    uint32_t base_node = BVH_INVALID;  // base-BVH node behind it (BVH_INVALID when loaded without one)
    uint32_t parent = NBVH_NO_CHILD;   // derived (not stored in the model file)
    uint32_t depth = 0;                // derived: root = 0
    uint8_t lod = NBVH_LOD_NONE;       // finest LoD at which this node is a leaf
    bool final_leaf = false;           // a base-BVH leaf: can never be split (official LEAF_FINAL)
    bool has_children() const { return left != NBVH_NO_CHILD; }
};

class NbvhTree {
public:
    NbvhTree() = default;
    // The cut starts at the root, or at every base node of depth `min_depth` (and shallower base leaves).
    NbvhTree(const Bvh& base, uint32_t lod_count = 1, uint32_t min_depth = 0);
    // From stored nodes (model file): only `bounds`, `left`, `lod` and `final_leaf` (and optionally
    // `base_node`) are read; parent and depth are derived. Structure is NBVH_CHECKed; the model reader
    // validates untrusted input before calling this.
    static NbvhTree from_nodes(std::vector<NbvhNode> nodes, uint32_t lod_count);

    const std::vector<NbvhNode>& nodes() const { return nodes_; }
    const NbvhNode& node(uint32_t i) const { return nodes_[i]; }
    uint32_t node_count() const { return uint32_t(nodes_.size()); }
    uint32_t lod_count() const { return lod_count_; }
    bool has_base() const { return base_ != nullptr; }

    // The current cut: nodes without children, in increasing node order. Recomputed on demand.
    std::vector<uint32_t> leaves() const;
    uint32_t leaf_count() const { return leaf_count_; }
    uint32_t max_depth() const;

    // Splitting (needs the base BVH, and refused once LoD 0 is registered: the cut is frozen).
    bool can_split(uint32_t node) const;
    // Replaces leaf `node` by its base-BVH children; returns their ids (left, left + 1).
    std::pair<uint32_t, uint32_t> split(uint32_t node);
    // Splits every node of `nodes` that can_split (duplicates and unsplittable ones are skipped, as the
    // official host code does); returns how many were split.
    uint32_t split_many(std::span<const uint32_t> nodes);

    // Levels of detail. register_lod() stamps the current cut as the next LoD (the first call registers
    // LoD lod_count-1, the last LoD 0) and returns its index; finish_lods() registers all remaining
    // LoDs with the current cut (duplicates, as the official code does with fewer learned LoDs).
    uint32_t register_lod();
    void finish_lods();
    uint32_t registered_lods() const { return registered_; }
    bool frozen() const { return registered_ == lod_count_; }
    // Is `node` a leaf when the cut of `lod` is walked (only meaningful for nodes reached by that walk)?
    bool is_leaf_at(uint32_t node, uint32_t lod) const {
        const NbvhNode& n = nodes_[node];
        return !n.has_children() || (n.lod != NBVH_LOD_NONE && lod >= n.lod);
    }
    // Nodes (interior + leaves) and leaves reached when walking the cut of `lod`.
    uint32_t node_count_at(uint32_t lod) const;
    std::vector<uint32_t> leaves_at(uint32_t lod) const;

    // Two-child GPU layout of the cut of `lod`: one GpuBvhNode per interior node of that cut, root first;
    // leaf references are nb_make_leaf(N-BVH node index, 1). A tree whose root is a leaf gives one GPU
    // node with the root as its left child and an empty right child.
    // `root`: the subtree of that node only (one asset of a multi-asset model); its first GPU node is its root.
    std::vector<GpuBvhNode> to_gpu_layout(uint32_t lod, uint32_t root = 0) const;

private:
    void derive_links();
    const Bvh* base_ = nullptr;
    std::vector<NbvhNode> nodes_;
    uint32_t lod_count_ = 1;
    uint32_t registered_ = 0;
    uint32_t leaf_count_ = 0;
};

} // namespace nbvh
