// A synthetic base BVH for tree-cut tests (no builder needed): a complete binary tree of a given depth
// over the unit cube, each node halving its parent's box along its longest axis. Leaves hold one
// primitive each.
#pragma once
#include <cstdint>

#include "engine/bvh/bvh.h"

namespace nbvh::test {

inline Bvh make_complete_bvh(uint32_t depth) {
    Bvh bvh;
    Aabb root;
    root.lo = glm::vec3(0.0f);
    root.hi = glm::vec3(1.0f);
    bvh.nodes.push_back({});
    bvh.nodes[0].bounds = root;
    // Breadth-first so parents precede children (any order would do for the N-BVH).
    for (uint32_t i = 0; i < bvh.nodes.size(); ++i) {
        if (bvh.nodes[i].depth == depth) {
            bvh.nodes[i].first = uint32_t(bvh.prim_indices.size());
            bvh.nodes[i].count = 1;
            bvh.prim_indices.push_back(uint32_t(bvh.prim_indices.size()));
            continue;
        }
        const Aabb b = bvh.nodes[i].bounds;
        const glm::vec3 e = b.extent();
        const int axis = (e.x >= e.y && e.x >= e.z) ? 0 : (e.y >= e.z ? 1 : 2);
        const float mid = 0.5f * (b.lo[axis] + b.hi[axis]);
        for (int side = 0; side < 2; ++side) {
            BvhNode c;
            c.bounds = b;
            (side == 0 ? c.bounds.hi : c.bounds.lo)[axis] = mid;
            c.parent = i;
            c.depth = bvh.nodes[i].depth + 1;
            (side == 0 ? bvh.nodes[i].left : bvh.nodes[i].right) = uint32_t(bvh.nodes.size());
            bvh.nodes.push_back(c);
        }
    }
    return bvh;
}

} // namespace nbvh::test
