// GPU layout of the triangle BLAS: a 4-wide node of 64 bytes whose child boxes are quantized to 8 bits
// per plane against the node's own frame (Ylitie, Karras, Laine 2017, "Efficient Incoherent Ray Traversal
// on GPUs Through Compressed Wide BVHs", reduced to 4 children). The binary SAH BVH (engine/bvh/bvh.h)
// is collapsed into it by engine/bvh/wide_bvh.cpp (to_wide_layout); the TLAS and the N-BVH stay binary
// (GpuBvhNode, bvh_node.h). One node fetch tests four child boxes instead of two, so a ray visits about
// half as many nodes for the same bytes per node.
//
// Child references are those of bvh_node.h (an interior node index, a leaf nb_make_leaf(first, count)
// with count <= NB_LEAF_MAX_COUNT, or NB_CHILD_NONE for an absent child).
//
// Child box i (absent children are skipped by their reference, never by their box):
//   lo = origin + float(q_lo_i) * scale,  hi = origin + float(q_hi_i) * scale   (per axis)
// where scale is a power of two per axis, so float(q) * scale is exact (q <= 255) and the only rounding
// is the addition (correctly rounded in IEEE, C++ and Vulkan alike; a fused multiply-add gives the same
// result because the product is exact). The builder picks each q so that the decoded box, computed with
// this very expression, contains the exact child box (rounded outward): a ray that hits a triangle hits
// every decoded box above it, and the box test itself keeps the numerics of intersect.h.
#ifndef NB_WIDE_BVH_NODE_H
#define NB_WIDE_BVH_NODE_H
#include "compat.h"
#include "bvh_node.h"
#include "intersect.h"

#define NB_WIDE_ARITY 4u
// Traversal stack: a path crosses at most NB_BVH_MAX_DEPTH wide nodes (each consumes at least one level
// of the binary tree, whose depth the builder bounds) and each pushes at most 3 far children.
#define NB_WIDE_STACK_SIZE (3u * NB_BVH_MAX_DEPTH)

// Quantized planes of child i in byte i (bits 8i..8i+7) of qlo_* / qhi_*.
struct GpuWideNode {
    vec3 origin; uint child0; // the node's box minimum (fp32) and child 0's reference
    vec3 scale; uint child1;  // per-axis quantization step (a power of two) and child 1's reference
    uint qlo_x; uint qlo_y; uint qlo_z; uint child2;
    uint qhi_x; uint qhi_y; uint qhi_z; uint child3;
};
NB_STATIC_ASSERT(sizeof(GpuWideNode) == 64, "GpuWideNode must be 64 bytes");

NB_FN uint nb_wide_child(GpuWideNode n, uint i) {
    return i == 0u ? n.child0 : (i == 1u ? n.child1 : (i == 2u ? n.child2 : n.child3));
}

// Byte i of `packed` as a float (exact: 0..255).
NB_FN float nb_wide_q(uint packed, uint i) { return float((packed >> (8u * i)) & 0xFFu); }

// Decoded (conservative) box of child i.
NB_FN void nb_wide_child_bounds(GpuWideNode n, uint i, NB_OUT(vec3) lo, NB_OUT(vec3) hi) {
    lo = n.origin + vec3(nb_wide_q(n.qlo_x, i), nb_wide_q(n.qlo_y, i), nb_wide_q(n.qlo_z, i)) * n.scale;
    hi = n.origin + vec3(nb_wide_q(n.qhi_x, i), nb_wide_q(n.qhi_y, i), nb_wide_q(n.qhi_z, i)) * n.scale;
}

// One nearest-first traversal of a wide BVH, written once for GLSL (shaders/lib/traverse.glsl) and the
// CPU mirror the tests run (engine/bvh/wide_bvh.cpp). NODES[i]: node i; ROOT: root node index; ORG,
// INV_DIR: the ray in the tree's space (INV_DIR = nb_safe_inv_dir); TMIN, TMAX: lvalues, the leaf
// handler narrows TMAX; DONE: lvalue, set by the handler to stop (any hit); LEAF(first, count): the leaf
// handler. Each node's hit children are sorted by entry distance (a 5-comparator network; misses carry
// +inf and sort last): the nearest is visited next, the others are pushed farthest first. A popped
// subtree behind a hit found meanwhile is culled when its node's boxes are tested (TMAX has shrunk),
// a popped leaf by its handler's own t tests.
#define NB_WIDE_CSWAP(TA, RA, TB, RB)                                                                \
    {                                                                                                \
        bool nb_s = TB < TA;                                                                         \
        float nb_ts = nb_s ? TB : TA;                                                                \
        uint nb_rs = nb_s ? RB : RA;                                                                 \
        TB = nb_s ? TA : TB;                                                                         \
        RB = nb_s ? RA : RB;                                                                         \
        TA = nb_ts;                                                                                  \
        RA = nb_rs;                                                                                  \
    }
// Entry distance of child I of node N (+inf when absent or missed) into T, its reference into R.
#define NB_WIDE_TEST(N, I, ORG, INV_DIR, TMIN, TMAX, T, R)                                          \
    {                                                                                                \
        vec3 nb_lo, nb_hi;                                                                           \
        nb_wide_child_bounds(N, I, nb_lo, nb_hi);                                                    \
        R = nb_wide_child(N, I);                                                                     \
        float nb_tn;                                                                                 \
        bool nb_h = R != NB_CHILD_NONE && nb_intersect_aabb(ORG, INV_DIR, nb_lo, nb_hi, TMIN, TMAX, nb_tn); \
        T = nb_h ? nb_tn : uintBitsToFloat(0x7F800000u);                                             \
        R = nb_h ? R : NB_CHILD_NONE;                                                                \
    }
#define NB_TRAVERSE_WIDE(NODES, ROOT, ORG, INV_DIR, TMIN, TMAX, DONE, LEAF)                          \
    {                                                                                                \
        uint nb_stack[NB_WIDE_STACK_SIZE];                                                           \
        uint nb_sp = 0u;                                                                             \
        uint nb_ref = (ROOT);                                                                        \
        while (!(DONE)) {                                                                            \
            if (nb_is_leaf(nb_ref)) {                                                                \
                LEAF(nb_leaf_first(nb_ref), nb_leaf_count(nb_ref));                                  \
                if (nb_sp == 0u) break;                                                              \
                nb_ref = nb_stack[--nb_sp];                                                          \
                continue;                                                                            \
            }                                                                                        \
            GpuWideNode nb_n = NODES[nb_ref];                                                        \
            float nb_t0, nb_t1, nb_t2, nb_t3;                                                        \
            uint nb_r0, nb_r1, nb_r2, nb_r3;                                                         \
            NB_WIDE_TEST(nb_n, 0u, ORG, INV_DIR, TMIN, TMAX, nb_t0, nb_r0)                           \
            NB_WIDE_TEST(nb_n, 1u, ORG, INV_DIR, TMIN, TMAX, nb_t1, nb_r1)                           \
            NB_WIDE_TEST(nb_n, 2u, ORG, INV_DIR, TMIN, TMAX, nb_t2, nb_r2)                           \
            NB_WIDE_TEST(nb_n, 3u, ORG, INV_DIR, TMIN, TMAX, nb_t3, nb_r3)                           \
            NB_WIDE_CSWAP(nb_t0, nb_r0, nb_t1, nb_r1)                                                \
            NB_WIDE_CSWAP(nb_t2, nb_r2, nb_t3, nb_r3)                                                \
            NB_WIDE_CSWAP(nb_t0, nb_r0, nb_t2, nb_r2)                                                \
            NB_WIDE_CSWAP(nb_t1, nb_r1, nb_t3, nb_r3)                                                \
            NB_WIDE_CSWAP(nb_t1, nb_r1, nb_t2, nb_r2)                                                \
            /* NB_WIDE_STACK_SIZE bounds the pushes (see above); the guard keeps memory safe */      \
            if (nb_r3 != NB_CHILD_NONE && nb_sp < NB_WIDE_STACK_SIZE) nb_stack[nb_sp++] = nb_r3;     \
            if (nb_r2 != NB_CHILD_NONE && nb_sp < NB_WIDE_STACK_SIZE) nb_stack[nb_sp++] = nb_r2;     \
            if (nb_r1 != NB_CHILD_NONE && nb_sp < NB_WIDE_STACK_SIZE) nb_stack[nb_sp++] = nb_r1;     \
            if (nb_r0 != NB_CHILD_NONE) {                                                            \
                nb_ref = nb_r0;                                                                      \
            } else {                                                                                 \
                if (nb_sp == 0u) break;                                                              \
                nb_ref = nb_stack[--nb_sp];                                                          \
            }                                                                                        \
        }                                                                                            \
    }

#endif
