#include "engine/neural/nbvh_tree.h"

#include <algorithm>
#include <set>

#include "engine/core/error.h"
#include "engine/core/log.h"

namespace nbvh {

namespace {
NbvhNode node_from_base(const Bvh& base, uint32_t id) {
    NbvhNode n;
    n.bounds = base.nodes[id].bounds;
    n.base_node = id;
    n.final_leaf = base.nodes[id].is_leaf();
    return n;
}

GpuBvhNode empty_gpu_node() {
    GpuBvhNode g{};
    g.lmin = vec3(NB_INF); g.lmax = vec3(-NB_INF);
    g.rmin = vec3(NB_INF); g.rmax = vec3(-NB_INF);
    g.left = NB_CHILD_NONE; g.right = NB_CHILD_NONE;
    g.pad0 = 0; g.pad1 = 0;
    return g;
}
} // namespace

NbvhTree::NbvhTree(const Bvh& base, uint32_t lod_count, uint32_t min_depth) : base_(&base), lod_count_(lod_count) {
    if (base.empty()) throw Error("cannot build an N-BVH: the base BVH is empty (no valid triangles)");
    if (lod_count == 0 || lod_count > NBVH_MAX_LODS)
        throw Error(strfmt("N-BVH level-of-detail count %u must be in [1, %u]", lod_count, NBVH_MAX_LODS));
    nodes_.push_back(node_from_base(base, 0));
    leaf_count_ = 1;
    // Initial cut at `min_depth` (official neural_bvh_min_depth, 0 = the root alone).
    for (uint32_t i = 0; i < nodes_.size(); ++i)
        if (nodes_[i].depth < min_depth && can_split(i)) split(i);
}

NbvhTree NbvhTree::from_nodes(std::vector<NbvhNode> nodes, uint32_t lod_count) {
    NBVH_CHECK(!nodes.empty() && nodes.size() <= NBVH_MAX_NODES);
    NBVH_CHECK(lod_count >= 1 && lod_count <= NBVH_MAX_LODS);
    NbvhTree t;
    t.nodes_ = std::move(nodes);
    t.lod_count_ = lod_count;
    t.registered_ = lod_count; // a stored tree is final
    t.derive_links();
    return t;
}

void NbvhTree::derive_links() {
    leaf_count_ = 0;
    nodes_[0].parent = NBVH_NO_CHILD;
    nodes_[0].depth = 0;
    for (uint32_t i = 0; i < nodes_.size(); ++i) {
        NbvhNode& n = nodes_[i];
        if (!n.has_children()) { leaf_count_++; continue; }
        NBVH_CHECK(n.left > i && n.left + 1 < nodes_.size()); // children after their parent
        for (uint32_t c = n.left; c <= n.left + 1; ++c) {
            nodes_[c].parent = i;
            nodes_[c].depth = n.depth + 1;
        }
    }
}

std::vector<uint32_t> NbvhTree::leaves() const {
    std::vector<uint32_t> out;
    out.reserve(leaf_count_);
    for (uint32_t i = 0; i < nodes_.size(); ++i)
        if (!nodes_[i].has_children()) out.push_back(i);
    return out;
}

uint32_t NbvhTree::max_depth() const {
    uint32_t d = 0;
    for (const NbvhNode& n : nodes_) d = std::max(d, n.depth);
    return d;
}

bool NbvhTree::can_split(uint32_t node) const {
    if (!base_ || frozen() || node >= nodes_.size()) return false;
    const NbvhNode& n = nodes_[node];
    return !n.has_children() && !n.final_leaf && nodes_.size() + 2 <= NBVH_MAX_NODES;
}

std::pair<uint32_t, uint32_t> NbvhTree::split(uint32_t node) {
    NBVH_CHECK_MSG(can_split(node), "split of a node that is not a splittable leaf");
    const BvhNode& b = base_->nodes[nodes_[node].base_node];
    NBVH_CHECK(b.left < base_->nodes.size() && b.right < base_->nodes.size());
    const uint32_t l = uint32_t(nodes_.size());
    for (uint32_t child : {b.left, b.right}) {
        NbvhNode c = node_from_base(*base_, child);
        c.parent = node;
        c.depth = nodes_[node].depth + 1;
        nodes_.push_back(c);
    }
    nodes_[node].left = l; // keeps its `lod`: still a leaf at the coarser LoDs already registered
    leaf_count_ += 1;
    return {l, l + 1};
}

uint32_t NbvhTree::split_many(std::span<const uint32_t> nodes) {
    std::set<uint32_t> unique(nodes.begin(), nodes.end());
    uint32_t done = 0;
    for (uint32_t n : unique)
        if (can_split(n)) { split(n); done++; }
    return done;
}

uint32_t NbvhTree::register_lod() {
    NBVH_CHECK_MSG(!frozen(), "every level of detail is already registered");
    const uint32_t lod = lod_count_ - 1 - registered_;
    for (NbvhNode& n : nodes_)
        if (!n.has_children()) n.lod = uint8_t(lod);
    registered_++;
    return lod;
}

void NbvhTree::finish_lods() {
    while (!frozen()) register_lod();
}

// Walks the cut of `lod` from the root; visit(node, is_leaf).
template <class F> static void walk_cut(const NbvhTree& t, uint32_t lod, F&& visit) {
    std::vector<uint32_t> stack{0};
    while (!stack.empty()) {
        const uint32_t i = stack.back();
        stack.pop_back();
        const bool leaf = t.is_leaf_at(i, lod);
        visit(i, leaf);
        if (!leaf) {
            stack.push_back(t.node(i).left + 1);
            stack.push_back(t.node(i).left);
        }
    }
}

uint32_t NbvhTree::node_count_at(uint32_t lod) const {
    uint32_t count = 0;
    walk_cut(*this, lod, [&](uint32_t, bool) { count++; });
    return count;
}

std::vector<uint32_t> NbvhTree::leaves_at(uint32_t lod) const {
    std::vector<uint32_t> out;
    walk_cut(*this, lod, [&](uint32_t i, bool leaf) { if (leaf) out.push_back(i); });
    return out;
}

std::vector<GpuBvhNode> NbvhTree::to_gpu_layout(uint32_t lod, uint32_t root) const {
    std::vector<GpuBvhNode> gpu;
    if (nodes_.empty()) return gpu;
    NBVH_CHECK(root < nodes_.size());
    if (is_leaf_at(root, lod)) {
        GpuBvhNode g = empty_gpu_node();
        g.lmin = nodes_[root].bounds.lo; g.lmax = nodes_[root].bounds.hi;
        g.left = nb_make_leaf(root, 1);
        gpu.push_back(g);
        return gpu;
    }
    // Depth-first, left subtree first, so a GPU node's left child (when interior) is the next node.
    struct Item { uint32_t node; uint32_t gpu_parent; bool is_right; };
    std::vector<Item> stack{{root, NB_CHILD_NONE, false}};
    while (!stack.empty()) {
        const Item it = stack.back();
        stack.pop_back();
        const uint32_t gi = uint32_t(gpu.size());
        if (it.gpu_parent != NB_CHILD_NONE) {
            GpuBvhNode& p = gpu[it.gpu_parent];
            (it.is_right ? p.right : p.left) = gi;
        }
        const NbvhNode& n = nodes_[it.node];
        GpuBvhNode g = empty_gpu_node();
        const NbvhNode& l = nodes_[n.left];
        const NbvhNode& r = nodes_[n.left + 1];
        g.lmin = l.bounds.lo; g.lmax = l.bounds.hi;
        g.rmin = r.bounds.lo; g.rmax = r.bounds.hi;
        g.left = is_leaf_at(n.left, lod) ? nb_make_leaf(n.left, 1) : NB_CHILD_NONE;
        g.right = is_leaf_at(n.left + 1, lod) ? nb_make_leaf(n.left + 1, 1) : NB_CHILD_NONE;
        gpu.push_back(g);
        if (!is_leaf_at(n.left + 1, lod)) stack.push_back({n.left + 1, gi, true});
        if (!is_leaf_at(n.left, lod)) stack.push_back({n.left, gi, false});
    }
    return gpu;
}

} // namespace nbvh
