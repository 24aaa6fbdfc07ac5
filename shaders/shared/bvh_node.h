// GPU layout of every BVH in nbvh (BLAS over triangles, TLAS over instances, N-BVH over neural
// leaves): a two-child node of 64 bytes that stores the bounds of both children, so one node fetch
// decides which children to visit (tinybvh's "BVH_GPU" layout). Traversal is the same for all three;
// what a leaf contains is up to the caller's leaf handler (madmann91/bvh).
#ifndef NB_BVH_NODE_H
#define NB_BVH_NODE_H
#include "compat.h"

// A child reference: an interior node index, or (bit 31 set) a leaf: NB_LEAF_FIRST_BITS bits of
// first item (primitive/instance/neural-leaf index) and 4 bits of (count - 1).
#define NB_LEAF_BIT 0x80000000u
#define NB_LEAF_FIRST_BITS 27u
#define NB_LEAF_FIRST_MASK 0x07FFFFFFu
#define NB_LEAF_MAX_COUNT 16u
// Reference to nothing: bounds of an absent child are stored empty (lo > hi) so no ray enters it.
#define NB_CHILD_NONE 0xFFFFFFFFu
// Maximal traversal stack depth (the builder guarantees trees no deeper than this).
#define NB_BVH_MAX_DEPTH 64u

struct GpuBvhNode {
    vec3 lmin; uint left;   // left child bounds (min) and reference
    vec3 lmax; uint right;  // left child bounds (max) and right child reference
    vec3 rmin; uint pad0;
    vec3 rmax; uint pad1;
};
NB_STATIC_ASSERT(sizeof(GpuBvhNode) == 64, "GpuBvhNode must be 64 bytes");

NB_FN bool nb_is_leaf(uint ref) { return (ref & NB_LEAF_BIT) != 0u && ref != NB_CHILD_NONE; }
NB_FN uint nb_leaf_first(uint ref) { return ref & NB_LEAF_FIRST_MASK; }
NB_FN uint nb_leaf_count(uint ref) { return ((ref >> NB_LEAF_FIRST_BITS) & 0xFu) + 1u; }
NB_FN uint nb_make_leaf(uint first, uint count) {
    return NB_LEAF_BIT | (((count - 1u) & 0xFu) << NB_LEAF_FIRST_BITS) | (first & NB_LEAF_FIRST_MASK);
}

#endif
