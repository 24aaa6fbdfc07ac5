// Generic CPU traversal of a Bvh (madmann91/bvh style): the traversal only knows boxes; what a leaf
// contains is decided by the caller's leaf callback. Triangle BLAS, instance TLAS, the N-BVH cut
// ("first leaf of the cut the ray meets") and the CPU trainer all use these two functions.
// Box tests are nb_intersect_aabb from shaders/shared/intersect.h (the same math as the GPU).
#pragma once
#include <cstdint>

#include "engine/bvh/bvh.h"
#include "engine/core/error.h"
#include "shaders/shared/intersect.h"

namespace nbvh {

// A ray org + t * dir. dir need not be normalised; all t are in units of |dir|.
struct Ray {
    glm::vec3 org{0.0f};
    glm::vec3 dir{0.0f, 0.0f, 1.0f};
};

// Traverses nodes nearest-first (by box entry distance) and calls
//     bool leaf_fn(uint32_t node_index, float t_near, float& tmax)
// for every node with is_leaf(node_index) true whose box the ray meets within [tmin, tmax].
// t_near is the entry distance into that node's box (>= tmin). The callback may shrink tmax
// (closest hit: later boxes beyond it are culled) and returns true to stop the traversal
// (any hit, or "first cut leaf"). is_leaf must return true at least for real leaves
// (BvhNode::is_leaf()); returning true for interior nodes treats them as leaves (an N-BVH cut).
// Returns the final tmax.
template <class IsLeaf, class LeafFn>
float traverse_cut(const Bvh& bvh, const Ray& ray, float tmin, float tmax, IsLeaf&& is_leaf, LeafFn&& leaf_fn) {
    if (bvh.nodes.empty()) return tmax;
    const glm::vec3 inv = nb_safe_inv_dir(ray.dir);
    struct Entry {
        uint32_t node;
        float t_near;
    };
    // Depth < NB_BVH_MAX_DEPTH (builder guarantee) bounds the stack: at most one far child per level.
    Entry stack[NB_BVH_MAX_DEPTH + 1];
    uint32_t size = 0;
    float t_root;
    if (!nb_intersect_aabb(ray.org, inv, bvh.nodes[0].bounds.lo, bvh.nodes[0].bounds.hi, tmin, tmax, t_root))
        return tmax;
    stack[size++] = Entry{0, t_root};
    while (size > 0) {
        const Entry e = stack[--size];
        if (e.t_near > tmax) continue; // culled by a closer hit found after it was pushed
        uint32_t ni = e.node;
        float t_near = e.t_near;
        for (;;) {
            const BvhNode& n = bvh.nodes[ni];
            if (n.is_leaf() || is_leaf(ni)) {
                if (leaf_fn(ni, t_near, tmax)) return tmax;
                break;
            }
            const BvhNode& l = bvh.nodes[n.left];
            const BvhNode& r = bvh.nodes[n.right];
            float tl, tr;
            bool hl = nb_intersect_aabb(ray.org, inv, l.bounds.lo, l.bounds.hi, tmin, tmax, tl);
            bool hr = nb_intersect_aabb(ray.org, inv, r.bounds.lo, r.bounds.hi, tmin, tmax, tr);
            if (hl && hr) {
                // Visit the nearer child now, push the farther (ties: left first, deterministic).
                bool left_first = tl <= tr;
                NBVH_CHECK(size < NB_BVH_MAX_DEPTH + 1);
                stack[size++] = left_first ? Entry{n.right, tr} : Entry{n.left, tl};
                ni = left_first ? n.left : n.right;
                t_near = left_first ? tl : tr;
            } else if (hl) {
                ni = n.left;
                t_near = tl;
            } else if (hr) {
                ni = n.right;
                t_near = tr;
            } else {
                break;
            }
        }
    }
    return tmax;
}

// traverse_cut over the real leaves of the BVH.
template <class LeafFn>
float traverse(const Bvh& bvh, const Ray& ray, float tmin, float tmax, LeafFn&& leaf_fn) {
    return traverse_cut(bvh, ray, tmin, tmax, [](uint32_t) { return false; }, leaf_fn);
}

} // namespace nbvh
