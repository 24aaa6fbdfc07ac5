// Bvh queries, bounds padding and the conversion to the two-child GPU layout (bvh_node.h).
#include <algorithm>
#include <cfloat>

#include "engine/bvh/aabb_ops.h"
#include "engine/bvh/bvh.h"
#include "engine/core/error.h"

namespace nbvh {

uint32_t Bvh::max_depth() const {
    uint32_t d = 0;
    for (const BvhNode& n : nodes) d = std::max(d, n.depth);
    return d;
}

void pad_node_bounds(Bvh& bvh, float min_extent) {
    if (!(min_extent > 0.0f)) return;
    for (BvhNode& n : bvh.nodes) n.bounds = pad_degenerate(n.bounds, min_extent);
    // Children are stored after their parents: a reverse sweep regrows every parent over its
    // (padded) children, so containment holds again.
    for (size_t i = bvh.nodes.size(); i-- > 1;) {
        const BvhNode& n = bvh.nodes[i];
        if (n.parent != BVH_INVALID) bvh.nodes[n.parent].bounds.grow(n.bounds);
    }
}

namespace {

uint32_t leaf_ref(const BvhNode& n) {
    NBVH_CHECK(n.count >= 1 && n.count <= NB_LEAF_MAX_COUNT && n.first <= NB_LEAF_FIRST_MASK);
    return nb_make_leaf(n.first, n.count);
}

} // namespace

std::vector<GpuBvhNode> to_gpu_layout(const Bvh& bvh) {
    std::vector<GpuBvhNode> out;
    if (bvh.nodes.empty()) return out;
    const BvhNode& root = bvh.nodes[0];
    if (root.is_leaf()) {
        GpuBvhNode g{};
        g.lmin = root.bounds.lo;
        g.lmax = root.bounds.hi;
        g.left = leaf_ref(root);
        g.right = NB_CHILD_NONE;
        g.rmin = glm::vec3(FLT_MAX);
        g.rmax = glm::vec3(-FLT_MAX);
        out.push_back(g);
        return out;
    }
    // GPU index of each interior CPU node, assigned in depth-first order (root first) so that a
    // subtree is contiguous and the near child of a node usually follows it.
    std::vector<uint32_t> gpu_index(bvh.nodes.size(), NB_CHILD_NONE);
    std::vector<uint32_t> order;
    std::vector<uint32_t> stack{0};
    while (!stack.empty()) {
        uint32_t ni = stack.back();
        stack.pop_back();
        const BvhNode& n = bvh.nodes[ni];
        if (n.is_leaf()) continue;
        gpu_index[ni] = uint32_t(order.size());
        order.push_back(ni);
        stack.push_back(n.right);
        stack.push_back(n.left);
    }
    out.resize(order.size());
    for (size_t g = 0; g < order.size(); ++g) {
        const BvhNode& n = bvh.nodes[order[g]];
        const BvhNode& l = bvh.nodes[n.left];
        const BvhNode& r = bvh.nodes[n.right];
        GpuBvhNode& o = out[g];
        o = GpuBvhNode{};
        o.lmin = l.bounds.lo;
        o.lmax = l.bounds.hi;
        o.rmin = r.bounds.lo;
        o.rmax = r.bounds.hi;
        o.left = l.is_leaf() ? leaf_ref(l) : gpu_index[n.left];
        o.right = r.is_leaf() ? leaf_ref(r) : gpu_index[n.right];
        o.pad0 = o.pad1 = 0;
    }
    return out;
}

} // namespace nbvh
