// Hash-grid features of the 3 segment points (paper §4), for both neural query kernels.
// All index/weight arithmetic comes from shared/hashgrid.h; this file only fetches and accumulates, with
// the fp16 rounding point R1 of shared/mlp.h: fp16 grid values, fp32 corner weights, fp32 sum over
// corners 0..7, one rounding to fp16 per level and feature.
//
// The including shader declares (scalar layout, any binding):
//   GpuHashLevel neural_levels[];  // NB_GRID_MAX_LEVELS entries
//   uvec2 neural_grid[];           // one entry = 4 fp16 features packed in 2 words (neural_gpu.h)
#ifndef NB_NEURAL_GRID_GLSL
#define NB_NEURAL_GRID_GLSL
#include "shared/hashgrid.h"
#include "shared/neural_query.h"
#include "shared/neural_gpu.h"


// Round to the nearest fp16 value (round to nearest even on every conformant implementation: the
// conversion of packHalf2x16 is correctly rounded in Vulkan). Saturates to +-inf like fp16.
float nb_round_half(float x) { return unpackHalf2x16(packHalf2x16(vec2(x, 0.0f))).x; }

// The 4 features of level l of one encoded point, each already rounded to fp16.
vec4 nb_neural_level_features(vec3 p, uint l) {
    GpuHashLevel lv = neural_levels[l];
    uvec3 cell;
    vec3 frac;
    nb_grid_position(lv, p, cell, frac);
    vec4 sum = vec4(0.0f);
    for (uint c = 0u; c < NB_GRID_CORNERS; ++c) {
        float w = nb_grid_corner_weight(frac, c);
        uvec2 e = neural_grid[nb_grid_corner_entry(lv, cell, c)];
        vec4 v = vec4(unpackHalf2x16(e.x), unpackHalf2x16(e.y));
        // Separate multiply and add per component, in corner order (the CPU reference's order).
        sum.x += w * v.x;
        sum.y += w * v.y;
        sum.z += w * v.z;
        sum.w += w * v.w;
    }
    return vec4(nb_round_half(sum.x), nb_round_half(sum.y), nb_round_half(sum.z), nb_round_half(sum.w));
}

// Same value as nb_neural_level_features (same corner order and rounding), for the fast cooperative-matrix
// kernels: all 8 corner entries of the level are loaded before any is used, so 8 independent gather
// loads are in flight per invocation (H200, results/neural/README.md v15: +4 % queries/s; 2 or 4 at a
// time gained nothing). The scalar kernel keeps the rolled loop above.
#ifdef NB_COOP_ACC_BITS
#extension GL_EXT_control_flow_attributes : require
vec4 nb_neural_level_features_batched(vec3 p, uint l) {
    GpuHashLevel lv = neural_levels[l];
    uvec3 cell;
    vec3 frac;
    nb_grid_position(lv, p, cell, frac);
    vec4 sum = vec4(0.0f);
    // A loop of ONE iteration on purpose: the same code without it (straight-line) ran 0.43 instead of
    // 0.57 G queries/s (v15 run 2), presumably because the driver then schedules the level loop around it
    // differently (more registers, fewer resident warps).
    for (uint c0 = 0u; c0 < NB_GRID_CORNERS; c0 += NB_GRID_CORNERS) {
        uvec2 e[NB_GRID_CORNERS];
        [[unroll]] for (uint c = 0u; c < NB_GRID_CORNERS; ++c) e[c] = neural_grid[nb_grid_corner_entry(lv, cell, c0 + c)];
        [[unroll]] for (uint c = 0u; c < NB_GRID_CORNERS; ++c) {
            float w = nb_grid_corner_weight(frac, c0 + c);
            vec4 v = vec4(unpackHalf2x16(e[c].x), unpackHalf2x16(e[c].y));
            sum.x += w * v.x;
            sum.y += w * v.y;
            sum.z += w * v.z;
            sum.w += w * v.w;
        }
    }
    return vec4(nb_round_half(sum.x), nb_round_half(sum.y), nb_round_half(sum.z), nb_round_half(sum.w));
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
GpuNeuralHit nb_neural_decode(GpuEncodingBox box, float y[NB_MLP_OUTPUTS], float t_entry, float t_exit,
                              float threshold) {
    GpuNeuralHit h;
    h.visibility = y[NB_OUT_VISIBILITY];
    h.depth = y[NB_OUT_DEPTH];
    h.normal = nb_decode_normal(y[NB_OUT_NORMAL], y[NB_OUT_NORMAL + 1u], y[NB_OUT_NORMAL + 2u]);
    h.albedo = vec3(y[NB_OUT_ALBEDO], y[NB_OUT_ALBEDO + 1u], y[NB_OUT_ALBEDO + 2u]);
    float t_hit;
    bool accepted = nb_decode_depth(box, y[NB_OUT_DEPTH], t_entry, t_exit, t_hit);
    h.t = t_hit;
    h.flags = (nb_decode_visibility(y[NB_OUT_VISIBILITY], threshold) ? NB_NEURAL_VISIBLE : 0u) |
              (accepted ? NB_NEURAL_ACCEPTED : 0u);
    h.pad0 = 0u;
    h.pad1 = 0u;
    return h;
}

#endif
