// Hash-grid features of the 3 segment points (paper §4), for both neural query kernels.
// All index/weight arithmetic comes from shared/hashgrid.h; this file only fetches and accumulates, with
// the fp16 rounding point R1 of shared/mlp.h: fp16 grid values, fp32 corner weights, fp32 sum over
// corners 0..7, one rounding to fp16 per level and feature.
//
// The including shader declares (any binding):
//   uvec4 neural_levels[];         // std430: NB_GRID_MAX_LEVELS levels, packed by nb_level_pack, then the
//                                  // y-pair word NB_LEVEL_YPAIR_WORD (shared/hashgrid.h)
//   uvec2 neural_grid[];           // scalar: one entry = 4 fp16 features packed in 2 words (neural_gpu.h)
//   uvec4 neural_grid_y[];         // with NB_GATHER_YPAIR: the same buffer in 16-byte words (the y-pair table)
#ifndef NB_NEURAL_GRID_GLSL
#define NB_NEURAL_GRID_GLSL
#include "shared/hashgrid.h"
#include "shared/neural_query.h"
#include "shared/neural_gpu.h"


// Level l's parameters in one 16-byte load (shared/hashgrid.h nb_level_pack; a scalar-layout
// GpuHashLevel took five 4-byte loads per level and point; the subgroup's lanes all read the same level).
GpuHashLevel nb_neural_level(uint l) { return nb_level_unpack(neural_levels[l]); }

// Round to the nearest fp16 value (round to nearest even on every conformant implementation: the
// conversion of packHalf2x16 is correctly rounded in Vulkan). Saturates to +-inf like fp16.
float nb_round_half(float x) { return unpackHalf2x16(packHalf2x16(vec2(x, 0.0f))).x; }

// The 4 features of level l of one encoded point, each already rounded to fp16.
vec4 nb_neural_level_features(vec3 p, uint l) {
    GpuHashLevel lv = nb_neural_level(l);
    uvec3 cell;
    vec3 frac;
    nb_grid_position(lv, p, cell, frac);
    uvec2 e[NB_GRID_CORNERS];
#ifdef NB_GATHER_YPAIR
    uvec4 yp = neural_levels[NB_LEVEL_YPAIR_WORD]; // (table base, y-paired levels, 0, 0)
    if (l < yp.y) {
        // Corners c and c|2 in one load (shared/hashgrid.h y-pair table); the same words.
        for (uint k = 0u; k < 4u; ++k) {
            uint c = (k & 1u) | ((k & 2u) << 1u); // corners 0, 1, 4, 5 (y bit 0)
            uvec4 t = neural_grid_y[yp.x + nb_grid_corner_entry(lv, cell, c)];
            e[c] = t.xy;
            e[c + 2u] = t.zw;
        }
    } else
#endif
    for (uint c = 0u; c < NB_GRID_CORNERS; ++c) e[c] = neural_grid[nb_grid_corner_entry(lv, cell, c)];
    vec4 sum = vec4(0.0f);
    for (uint c = 0u; c < NB_GRID_CORNERS; ++c) {
        float w = nb_grid_corner_weight(frac, c);
        vec4 v = vec4(unpackHalf2x16(e[c].x), unpackHalf2x16(e[c].y));
        // Separate multiply and add per component, in corner order (the CPU reference's order).
        sum.x += w * v.x;
        sum.y += w * v.y;
        sum.z += w * v.z;
        sum.w += w * v.w;
    }
    return vec4(nb_round_half(sum.x), nb_round_half(sum.y), nb_round_half(sum.z), nb_round_half(sum.w));
}

// Fast gather of the fp32 cooperative-matrix kernel (NB_COOP_ACC_BITS defined; subgroups of 32, checked
// on the host). It fetches NB_GATHER_LEVELS levels of a point at once, so that 8 * NB_GATHER_LEVELS
// independent loads are in flight per invocation: the fused kernel's registers are set by the MLP
// (168 per invocation on the H200, 12 warps per SM), which leaves the gather phase room for many loads
// in flight, and that phase has to hide the gather latency with few resident warps (v17: 1 -> 2 -> 4
// levels at once, 0.81 -> 0.87 -> 0.88 G queries/s random, 0.99 -> 1.05 -> 1.12 coherent).
#ifdef NB_COOP_ACC_BITS
#extension GL_EXT_control_flow_attributes : require
#extension GL_KHR_shader_subgroup_shuffle : require
#ifndef NB_GATHER_LEVELS
#define NB_GATHER_LEVELS 4u
#endif

// Paired-lane gather: the 2 lanes of a pair (lane ^ 1) look up BOTH their queries' levels together:
// the even lane loads the corners with x bit 0 (0, 2, 4, 6), the odd lane those with x bit 1 (1, 3, 5,
// 7). Corners c and c|1 differ only in x, and both index schemes (dense x + ..., CoherentPrime x * 1 ^
// ...) keep them in the same 128-byte line 15 times out of 16, so one load instruction of the subgroup
// touches ~16 lines instead of 32: random gathers are bound by L1 requests (lines), which this halves
// (H200, results/neural v17: gather alone 0.84 -> 1.15 G/s). Each lane sums its 4 corners per query in
// corner order (fp32); the pair swaps the partial sums of each other's query; a level's feature =
// sum(even corners) + sum(odd corners), rounded once to fp16 (R1). That order differs from the
// reference's 0..7 chain, so a feature can differ by one fp16 ulp from the CPU reference (the coopmat
// MLP sums in another order too; tests/neuralvk bounds both). All 32 lanes must be active (shuffles).
// The paired lanes' sums of the loaded corners (see nb_neural_levels_paired): each lane's 4 corners of
// both queries in corner order, then the partner's partial of its own query.
void nb_neural_paired_sums(uvec2 ea[NB_GATHER_LEVELS * 4u], uvec2 eb[NB_GATHER_LEVELS * 4u], vec3 fa[NB_GATHER_LEVELS],
                           vec3 fb[NB_GATHER_LEVELS], uint xbit, out vec4 f[NB_GATHER_LEVELS]) {
    [[unroll]] for (uint g = 0u; g < NB_GATHER_LEVELS; ++g) {
        vec4 sa = vec4(0.0f);
        vec4 sb = vec4(0.0f);
        [[unroll]] for (uint j = 0u; j < 4u; ++j) {
            uvec2 xa = ea[g * 4u + j];
            uvec2 xb = eb[g * 4u + j];
            sa += nb_grid_corner_weight(fa[g], 2u * j + xbit) * vec4(unpackHalf2x16(xa.x), unpackHalf2x16(xa.y));
            sb += nb_grid_corner_weight(fb[g], 2u * j + xbit) * vec4(unpackHalf2x16(xb.x), unpackHalf2x16(xb.y));
        }
        // The even lane owns query a, the odd lane query b: each sends the partial of its partner's query.
        vec4 other = subgroupShuffleXor(xbit == 0u ? sb : sa, 1u);
        vec4 sum = (xbit == 0u ? sa : sb) + other; // even + odd in both lanes (addition commutes exactly)
        f[g] = vec4(nb_round_half(sum.x), nb_round_half(sum.y), nb_round_half(sum.z), nb_round_half(sum.w));
    }
}

// The body of nb_neural_levels_paired and its y-pair form: each level g of the batch's cells (ca, cb)
// and fractions of both queries, then LOAD (ea and eb [g * 4 .. g * 4 + 3]: the lane's 4 corners of each
// query), then the sums. Each form instantiates it whole: a form that chose the loads per batch and then
// summed once took the gather kernel from 56 to 127 registers (the loaded words merged from the two
// paths; results/neural/ypair_variants_h200.txt). LOAD must hold no comma outside parentheses (one macro
// argument).
// A loop of ONE iteration on purpose: the same code without it (straight-line) ran 0.43 instead of 0.57 G
// queries/s in the v15 kernel (results/neural/README.md), presumably because the driver then schedules the
// level loop around it differently (more registers, fewer resident warps).
#define NB_PAIRED_LEVELS_BODY(LOAD)                                                                   \
    for (uint once = 0u; once < 1u; ++once) {                                                         \
        uvec2 ea[NB_GATHER_LEVELS * 4u];                                                              \
        uvec2 eb[NB_GATHER_LEVELS * 4u];                                                              \
        vec3 fa[NB_GATHER_LEVELS];                                                                    \
        vec3 fb[NB_GATHER_LEVELS];                                                                    \
        [[unroll]] for (uint g = 0u; g < NB_GATHER_LEVELS; ++g) {                                     \
            GpuHashLevel lv = nb_neural_level(l0 + g);                                                \
            uvec3 ca, cb;                                                                             \
            nb_grid_position(lv, p_even, ca, fa[g]);                                                  \
            nb_grid_position(lv, p_odd, cb, fb[g]);                                                   \
            LOAD                                                                                      \
        }                                                                                             \
        nb_neural_paired_sums(ea, eb, fa, fb, xbit, f);                                               \
    }

#ifdef NB_GATHER_YPAIR
// nb_neural_levels_paired for a batch of levels that all have y-pair entries (shared/hashgrid.h; the
// includer declares `uvec4 neural_grid_y[]` on the grid's binding): corners 2j + xbit and 2j + 2 + xbit
// (j = 0, 2: z and z + 1) in one 16-byte load, half the loads and lines; the same words, so the same sums.
void nb_neural_levels_paired_y(vec3 p_even, vec3 p_odd, uint l0, uint xbit, uint ybase, out vec4 f[NB_GATHER_LEVELS]) {
    NB_PAIRED_LEVELS_BODY([[unroll]] for (uint j = 0u; j < 4u; j += 2u) {
        uvec4 a = neural_grid_y[ybase + nb_grid_corner_entry(lv, ca, 2u * j + xbit)];
        uvec4 b = neural_grid_y[ybase + nb_grid_corner_entry(lv, cb, 2u * j + xbit)];
        ea[g * 4u + j] = a.xy;
        ea[g * 4u + j + 1u] = a.zw;
        eb[g * 4u + j] = b.xy;
        eb[g * 4u + j + 1u] = b.zw;
    })
}
#endif

void nb_neural_levels_paired(vec3 p_even, vec3 p_odd, uint l0, uint xbit, out vec4 f[NB_GATHER_LEVELS]) {
    NB_PAIRED_LEVELS_BODY([[unroll]] for (uint j = 0u; j < 4u; ++j) {
        ea[g * 4u + j] = neural_grid[nb_grid_corner_entry(lv, ca, 2u * j + xbit)];
        eb[g * 4u + j] = neural_grid[nb_grid_corner_entry(lv, cb, 2u * j + xbit)];
    })
}

// A level's 4 features (already fp16 values) as one 8-byte quad of the split query's features buffer.
uvec2 nb_split_quad(vec4 f) { return uvec2(packHalf2x16(f.xy), packHalf2x16(f.zw)); }

// The split query's gather (passes/neural_gather.comp, neural_eval_gather.comp): pair K's features of
// points P0..P2 into the features buffer (`uvec4 split_feature_tiles[]`, shared/neural_gpu.h
// nb_split_tile_word), one tile row (4 levels of a point: NB_GATHER_LEVELS must be 4) as two 16-byte
// stores; only where VALID (q_ is indexed by the unrolled level of the batch, g_, never dynamically).
// All 32 lanes must be active.
#define NB_SPLIT_GATHER_STORE(K, VALID, P0, P1, P2)                                                   \
    {                                                                                                 \
        uvec2 q_[NB_GATHER_LEVELS == 4u ? 4 : -1]; /* a tile row per batch: NB_GATHER_LEVELS must be 4 */ \
        NB_PAIRED_GATHER_SEGMENT(P0, P1, P2, q_[g_] = nb_split_quad(f); if (g_ == 3u && (VALID)) {      \
            uint w_ = nb_split_tile_word((K), (k * NB_GRID_MAX_LEVELS + l) / 4u);                    \
            split_feature_tiles[w_] = uvec4(q_[0], q_[1]);                                            \
            split_feature_tiles[w_ + 1u] = uvec4(q_[2], q_[3]);                                       \
        })                                                                                            \
    }

// One batch of levels through the y-pair table where every level of the batch has one.
#ifdef NB_GATHER_YPAIR
#define NB_PAIRED_LEVELS(PE, PO, L0, XBIT, F)                                                         \
    {                                                                                                 \
        uvec4 yp_ = neural_levels[NB_LEVEL_YPAIR_WORD]; /* (table base, y-paired levels, 0, 0) */     \
        if ((L0) + NB_GATHER_LEVELS <= yp_.y)                                                         \
            nb_neural_levels_paired_y(PE, PO, L0, XBIT, yp_.x, F);                                    \
        else                                                                                          \
            nb_neural_levels_paired(PE, PO, L0, XBIT, F);                                             \
    }
#else
#define NB_PAIRED_LEVELS(PE, PO, L0, XBIT, F) nb_neural_levels_paired(PE, PO, L0, XBIT, F);
#endif

// Runs BODY for every (point k, level l) of a segment's 3 points with `vec4 f` = that level's 4
// features (fp16-rounded), through the paired-lane gather, NB_GATHER_LEVELS levels of a point at a
// time (the fused query kernels stage f in shared memory, the split query's gather pass stores it).
// All 32 lanes must be active.
#define NB_PAIRED_GATHER_SEGMENT(P0, P1, P2, BODY)                                                    \
    {                                                                                                 \
        uint xbit_ = gl_SubgroupInvocationID & 1u;                                                    \
        for (uint k = 0u; k < NB_SEGMENT_POINTS; ++k) {                                               \
            vec3 p_ = k == 0u ? (P0) : (k == 1u ? (P1) : (P2));                                       \
            vec3 partner_ = subgroupShuffleXor(p_, 1u);                                               \
            vec3 p_even_ = xbit_ == 0u ? p_ : partner_;                                               \
            vec3 p_odd_ = xbit_ == 0u ? partner_ : p_;                                                \
            for (uint l0_ = 0u; l0_ < NB_GRID_MAX_LEVELS; l0_ += NB_GATHER_LEVELS) {                  \
                vec4 fs_[NB_GATHER_LEVELS];                                                           \
                NB_PAIRED_LEVELS(p_even_, p_odd_, l0_, xbit_, fs_);                                   \
                [[unroll]] for (uint g_ = 0u; g_ < NB_GATHER_LEVELS; ++g_) {                          \
                    uint l = l0_ + g_;                                                                \
                    vec4 f = fs_[g_];                                                                 \
                    BODY                                                                              \
                }                                                                                     \
            }                                                                                         \
        }                                                                                             \
    }
#endif

// The 32 features (level-major, 4 per level) of one encoded point.
void nb_neural_point_features(vec3 p, out float f[NB_POINT_FEATURES]) {
    for (uint l = 0u; l < NB_GRID_MAX_LEVELS; ++l) {
        vec4 v = nb_neural_level_features(p, l);
        f[l * 4u + 0u] = v.x;
        f[l * 4u + 1u] = v.y;
        f[l * 4u + 2u] = v.z;
        f[l * 4u + 3u] = v.w;
    }
}

// Decode the 8 outputs (after the sigmoid) of one query into a hit (shared/neural_query.h).
// dir_len: |direction| of the query's ray in the encoding space (nb_decode_depth).
GpuNeuralHit nb_neural_decode(GpuEncodingBox box, float y[NB_MLP_OUTPUTS], float t_entry, float t_exit,
                              float dir_len, float threshold) {
    GpuNeuralHit h;
    h.visibility = y[NB_OUT_VISIBILITY];
    h.depth = y[NB_OUT_DEPTH];
    h.normal = nb_decode_normal(y[NB_OUT_NORMAL], y[NB_OUT_NORMAL + 1u], y[NB_OUT_NORMAL + 2u]);
    h.albedo = vec3(y[NB_OUT_ALBEDO], y[NB_OUT_ALBEDO + 1u], y[NB_OUT_ALBEDO + 2u]);
    float t_hit;
    bool accepted = nb_decode_depth(box, y[NB_OUT_DEPTH], t_entry, t_exit, dir_len, t_hit);
    h.t = t_hit;
    h.flags = (nb_decode_visibility(y[NB_OUT_VISIBILITY], threshold) ? NB_NEURAL_VISIBLE : 0u) |
              (accepted ? NB_NEURAL_ACCEPTED : 0u);
    h.pad0 = 0u;
    h.pad1 = 0u;
    return h;
}

#endif
