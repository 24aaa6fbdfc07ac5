// Occupancy masks of the N-BVH nodes (a departure from the paper and the official code, which query
// every leaf a ray's segment crosses): each node that is a leaf at some LoD carries 8^3 bits over its
// box, one per cell, set when a triangle of the asset (the ground truth the network was trained on,
// official notes §6.7: the whole neural mesh over the leaf segment) touches the cell grown by
// NB_OCC_MARK_MARGIN of a cell (engine/neural/occupancy.cpp). A (ray, leaf) pair whose segment crosses
// only empty cells cannot have a true hit there and is not queried (lib/neural_traverse.glsl
// nb_neural_leaf): it skips the network where the network could only answer "miss" or be wrong.
//
// The walk (Amanatides & Woo) is shared by the GPU traversal and the host tests:
//   GpuOccWalk w = nb_occ_walk_begin(org, dir, lo, hi, t0, t1);
//   if (w.exact) do { uint bit = nb_occ_walk_bit(w); ...test it... } while (nb_occ_walk_next(w));
// t0 <= t1 is the part of the ray that can hold an accepted hit (the leaf interval clipped to tmin);
// the walk visits the cells of the segment in order. `exact` is false where float rounding of the
// grid coordinates could exceed NB_OCC_WALK_TOLERANCE of a cell (a tiny leaf far from the ray origin):
// such a pair is queried as without masks. Flat axes (zero extent) hold one cell; NaN or infinite
// inputs give exact = false.
#ifndef NB_NEURAL_OCCUPANCY_H
#define NB_NEURAL_OCCUPANCY_H
#include "compat.h"

#define NB_OCC_RES 8u                                         // cells per axis
#define NB_OCC_WORDS 16u                                      // 32-bit words per node (8^3 bits)
#define NB_OCC_MAX_STEPS 22u                                  // cells of one segment, at most 3 * 8 - 2
#define NB_OCC_WALK_TOLERANCE 0.015625f                       // 1/64 cell: rounding the walk may make
#define NB_OCC_MARK_MARGIN 0.03125f                           // 1/32 cell: how far marking grows a cell

// Bit of cell (x, y, z) in a node's 16 words: word bit >> 5, bit bit & 31.
NB_FN uint nb_occ_bit(uint x, uint y, uint z) { return x + NB_OCC_RES * (y + NB_OCC_RES * z); }

// Whether a cell's bit is set in the mask word that holds it (word bit >> 5 of the node's mask).
NB_FN bool nb_occ_is_set(uint word, uint bit) { return ((word >> (bit & 31u)) & 1u) != 0u; }

// Cells per unit length on each axis (0 on a flat axis: every point lies in its cell 0).
NB_FN vec3 nb_occ_scale(vec3 lo, vec3 hi) {
    vec3 e = hi - lo;
    float r = float(NB_OCC_RES);
    return vec3(e.x > 0.0f ? r / e.x : 0.0f, e.y > 0.0f ? r / e.y : 0.0f, e.z > 0.0f ? r / e.z : 0.0f);
}

// Cell index of grid coordinate g (clamped to the grid; NaN -> 0).
NB_FN int nb_occ_cell(float g) {
    if (!(g >= 1.0f)) return 0;
    return min(int(min(g, float(NB_OCC_RES) - 0.5f)), int(NB_OCC_RES) - 1);
}

// Whether a cell index is the grid's last one in the direction of `step` (no step can follow).
NB_FN bool nb_occ_at_edge(int cell, int step) { return step > 0 ? cell >= int(NB_OCC_RES) - 1 : cell <= 0; }

struct GpuOccWalk {
    ivec3 cell;
    ivec3 step;
    vec3 t_next;  // ray parameter of the next boundary on each axis
    vec3 t_delta; // ray parameter per cell on each axis
    float t_end;
    uint steps;
    bool exact;   // false: the caller must treat the segment as occupied (see the header comment)
};

NB_FN GpuOccWalk nb_occ_walk_begin(vec3 org, vec3 dir, vec3 lo, vec3 hi, float t0, float t1) {
    GpuOccWalk w;
    vec3 s = nb_occ_scale(lo, hi);
    vec3 p = (org + dir * t0 - lo) * s; // grid coordinates of the segment's start
    vec3 d = dir * s;                   // grid units per unit of t
    // Rounding of p (and of the boundary distances): a few ulps of the magnitudes involved, in cells.
    float tm = max(abs(t0), abs(t1));
    vec3 mag = abs(org) + abs(dir) * tm + abs(lo) + abs(hi);
    vec3 err = mag * s * 4.0e-7f;
    float worst = max(err.x, max(err.y, err.z));
    w.exact = worst <= NB_OCC_WALK_TOLERANCE && t0 <= t1 && abs(t0) < NB_INF && abs(t1) < NB_INF &&
              p.x == p.x && p.y == p.y && p.z == p.z && d.x == d.x && d.y == d.y && d.z == d.z;
    w.cell = ivec3(nb_occ_cell(p.x), nb_occ_cell(p.y), nb_occ_cell(p.z));
    w.t_end = t1;
    w.steps = 0u;
    for (int a = 0; a < 3; ++a) {
        if (d[a] > 0.0f) {
            w.step[a] = 1;
            w.t_next[a] = t0 + (float(w.cell[a] + 1) - p[a]) / d[a];
            w.t_delta[a] = 1.0f / d[a];
        } else if (d[a] < 0.0f) {
            w.step[a] = -1;
            w.t_next[a] = t0 + (float(w.cell[a]) - p[a]) / d[a];
            w.t_delta[a] = -1.0f / d[a];
        } else {
            w.step[a] = 0;
            w.t_next[a] = NB_INF;
            w.t_delta[a] = NB_INF;
        }
        if (w.step[a] != 0 && nb_occ_at_edge(w.cell[a], w.step[a])) w.t_next[a] = NB_INF;
    }
    return w;
}

NB_FN uint nb_occ_walk_bit(GpuOccWalk w) { return nb_occ_bit(uint(w.cell.x), uint(w.cell.y), uint(w.cell.z)); }

// Moves to the next cell of the segment; false when the segment ends. An axis whose cell is the grid's
// last one in its step direction takes no further step (t_next = inf, set here and by the begin): a
// segment grazing a face (it lies in the leaf box dilated by NB_LEAF_DILATION, and its start may round
// onto the face) keeps that boundary cell and the walk goes on along the other axes, instead of ending
// with cells of the segment unvisited.
NB_FN bool nb_occ_walk_next(NB_INOUT(GpuOccWalk) w) {
    int a = w.t_next.x <= w.t_next.y ? (w.t_next.x <= w.t_next.z ? 0 : 2) : (w.t_next.y <= w.t_next.z ? 1 : 2);
    // t_next >= NB_INF: every axis is done (also when t_end is infinite, in walks that are not exact).
    if (!(w.t_next[a] <= w.t_end) || w.t_next[a] >= NB_INF || w.steps >= NB_OCC_MAX_STEPS) return false;
    w.cell[a] += w.step[a];
    w.t_next[a] = nb_occ_at_edge(w.cell[a], w.step[a]) ? NB_INF : w.t_next[a] + w.t_delta[a];
    w.steps += 1u;
    return true;
}

#endif // NB_NEURAL_OCCUPANCY_H
