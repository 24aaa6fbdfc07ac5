// Set-0 bindings of the neural part of the wavefront renderer (shared/neural_gpu.h NB_BIND_NEURAL_*),
// included after lib/bindings.glsl by every pass that touches neural data. The weight buffer is seen as
// packed fp16 pairs (uint) unless the pass defines NB_NEURAL_MLP_AS_HALF before including this (the
// cooperative-matrix query pass, which reads the transposed copy, NB_BIND_NEURAL_MLP_T, as float16_t).
#ifndef NB_NEURAL_BINDINGS_GLSL
#define NB_NEURAL_BINDINGS_GLSL
#include "shared/hashgrid.h"
#include "shared/neural_gpu.h"

layout(set = 0, binding = NB_BIND_NEURAL_LEVELS, scalar) readonly buffer NeuralLevelBuffer { GpuHashLevel neural_levels[]; };
layout(set = 0, binding = NB_BIND_NEURAL_GRID, scalar) readonly buffer NeuralGridBuffer { uvec2 neural_grid[]; };
#ifdef NB_NEURAL_MLP_AS_HALF
#extension GL_EXT_shader_16bit_storage : require
#extension GL_EXT_shader_explicit_arithmetic_types_float16 : require
layout(set = 0, binding = NB_BIND_NEURAL_MLP_T, scalar) readonly buffer NeuralMlpBuffer { float16_t neural_mlp_h[]; };
#else
layout(set = 0, binding = NB_BIND_NEURAL_MLP, scalar) readonly buffer NeuralMlpBuffer { uint neural_mlp[]; };
#endif
layout(set = 0, binding = NB_BIND_NBVH_NODES, std430) readonly buffer NbvhNodeBuffer { GpuBvhNode nbvh_nodes[]; };
// Object-space bounds of every N-BVH node: lo at 2i, hi at 2i + 1.
layout(set = 0, binding = NB_BIND_NBVH_BOUNDS, scalar) readonly buffer NbvhBoundsBuffer { vec3 nbvh_bounds[]; };
// The same buffer as words: node i's occupancy mask (shared/neural_occupancy.h) is NB_OCC_WORDS words
// from neural_params.occupancy + NB_OCC_WORDS * i.
layout(set = 0, binding = NB_BIND_NBVH_BOUNDS, std430) readonly buffer NbvhBoundsWords { uint nbvh_bounds_words[]; };
layout(set = 0, binding = NB_BIND_NEURAL_STATE, scalar) buffer NeuralStateBuffer { GpuNeuralRayState neural_state[]; };
layout(set = 0, binding = NB_BIND_NEURAL_PARAMS, scalar) readonly buffer NeuralParamsBuffer { GpuNeuralParams neural_params; };
layout(set = 0, binding = NB_BIND_NEURAL_ASSETS, scalar) readonly buffer NeuralAssetBuffer { GpuNeuralAsset neural_assets[]; };
layout(set = 0, binding = NB_BIND_NEURAL_COUNTERS, scalar) coherent buffer NeuralCountersBuffer { GpuNeuralCounters neural_counters; };

// Slot k of half `half_` of the pending queue (each half holds leaves_per_round pairs per ray, in its
// own binding: half 1's slots start at the half size).
uint nb_nl_half_size() { return ray_capacity() * neural_params.leaves_per_round; }
uint nb_nl_pending_index(uint half_, uint k) { return half_ * nb_nl_half_size() + k; }
// Whole records are copied field by field: glslang emits an invalid whole-struct store between the two
// blocks' copies of the struct type (spirv-opt: "OpStore ... type does not match").
#define NB_PENDING_COPY(DST, SRC)                                                                    \
    DST.ray = SRC.ray;                                                                                \
    DST.instance = SRC.instance;                                                                      \
    DST.leaf = SRC.leaf;                                                                              \
    DST.t_enter = SRC.t_enter;                                                                        \
    DST.t_exit = SRC.t_exit;                                                                          \
    DST.group = SRC.group;                                                                            \
    DST.t = SRC.t;                                                                                    \
    DST.a = SRC.a;                                                                                    \
    DST.b = SRC.b;
GpuPendingLeaf nb_pending_load(uint slot) {
    uint hs = nb_nl_half_size();
    GpuPendingLeaf pl;
    if (slot < hs) {
        NB_PENDING_COPY(pl, pending_leaves[slot])
    } else {
        NB_PENDING_COPY(pl, pending_leaves_1[slot - hs])
    }
    return pl;
}
void nb_pending_store(uint slot, GpuPendingLeaf pl) {
    uint hs = nb_nl_half_size();
    if (slot < hs) {
        NB_PENDING_COPY(pending_leaves[slot], pl)
    } else {
        NB_PENDING_COPY(pending_leaves_1[slot - hs], pl)
    }
}
// The query pass's result of a pair. A miss (t NB_INF) stores t only: the resumed traversal takes a
// pair's normal and albedo only from a hit in front of its best one (nb_nl_take_hit).
void nb_pending_set_hit(uint slot, float t, vec3 normal, vec3 albedo) {
    uint hs = nb_nl_half_size();
    bool hit = t < NB_INF;
    if (slot < hs) {
        pending_leaves[slot].t = t;
        if (hit) {
            pending_leaves[slot].a = normal;
            pending_leaves[slot].b = albedo;
        }
    } else {
        pending_leaves_1[slot - hs].t = t;
        if (hit) {
            pending_leaves_1[slot - hs].a = normal;
            pending_leaves_1[slot - hs].b = albedo;
        }
    }
}

#endif
