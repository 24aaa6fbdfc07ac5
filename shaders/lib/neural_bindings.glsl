// Set-0 bindings of the neural part of the wavefront renderer (shared/neural_gpu.h NB_BIND_NEURAL_*),
// included after lib/bindings.glsl by every pass that touches neural data. The weight buffer is seen as
// packed fp16 pairs (uint) unless the pass defines NB_NEURAL_MLP_AS_TILES before including this (the
// cooperative-matrix query pass, which reads the transposed, tiled copy, NB_BIND_NEURAL_MLP_T, in
// 16-byte words: lib/neural_mlp_coopmat.glsl).
#ifndef NB_NEURAL_BINDINGS_GLSL
#define NB_NEURAL_BINDINGS_GLSL
#include "shared/hashgrid.h"
#include "shared/neural_gpu.h"

layout(set = 0, binding = NB_BIND_NEURAL_LEVELS, std430) readonly buffer NeuralLevelBuffer { uvec4 neural_levels[]; }; // GpuHashLevel (lib/neural_grid.glsl)
layout(set = 0, binding = NB_BIND_NEURAL_GRID, scalar) readonly buffer NeuralGridBuffer { uvec2 neural_grid[]; };
#ifdef NB_GATHER_YPAIR
// The same buffer in 16-byte words, for the y-pair table after the entries (shared/hashgrid.h).
layout(set = 0, binding = NB_BIND_NEURAL_GRID, std430) readonly buffer NeuralGridPairs { uvec4 neural_grid_y[]; };
#endif
#ifdef NB_NEURAL_MLP_AS_TILES
layout(set = 0, binding = NB_BIND_NEURAL_MLP_T, std430) readonly buffer NeuralMlpBuffer { uvec4 neural_mlp_tiles[]; };
#else
layout(set = 0, binding = NB_BIND_NEURAL_MLP, scalar) readonly buffer NeuralMlpBuffer { uint neural_mlp[]; };
#endif
layout(set = 0, binding = NB_BIND_NBVH_NODES, std430) readonly buffer NbvhNodeBuffer { GpuBvhNode nbvh_nodes[]; };
// Object-space bounds of every N-BVH node: (lo, 0) at 2i, (hi, 0) at 2i + 1 (NB_NBVH_BOUNDS_WORDS).
layout(set = 0, binding = NB_BIND_NBVH_BOUNDS, std430) readonly buffer NbvhBoundsBuffer { vec4 nbvh_bounds[]; };
// The same buffer as words: node i's occupancy mask (shared/neural_occupancy.h) is NB_OCC_WORDS words
// from neural_params.occupancy + NB_OCC_WORDS * i.
layout(set = 0, binding = NB_BIND_NBVH_BOUNDS, std430) readonly buffer NbvhBoundsWords { uint nbvh_bounds_words[]; };
// Per-ray neural state (GpuNeuralRayState, 64 bytes): 4 consecutive 16-byte words per ray, read and
// written whole by nb_state_load / nb_state_store below (a scalar-layout struct copy took 16 four-byte
// accesses each way).
layout(set = 0, binding = NB_BIND_NEURAL_STATE, std430) buffer NeuralStateBuffer { uvec4 neural_state[]; };
layout(set = 0, binding = NB_BIND_NEURAL_PARAMS, scalar) readonly buffer NeuralParamsBuffer { GpuNeuralParams neural_params; };
layout(set = 0, binding = NB_BIND_NEURAL_ASSETS, scalar) readonly buffer NeuralAssetBuffer { GpuNeuralAsset neural_assets[]; };
layout(set = 0, binding = NB_BIND_NEURAL_COUNTERS, scalar) coherent buffer NeuralCountersBuffer { GpuNeuralCounters neural_counters; };

GpuNeuralRayState nb_state_load(uint i) {
    uvec4 q0 = neural_state[4u * i], q1 = neural_state[4u * i + 1u];
    uvec4 q2 = neural_state[4u * i + 2u], q3 = neural_state[4u * i + 3u];
    GpuNeuralRayState st;
    st.normal = uintBitsToFloat(q0.xyz);
    st.best_t = uintBitsToFloat(q0.w);
    st.albedo_rg = q1.x;
    st.albedo_b = q1.y;
    st.hit_leaf = q1.z;
    st.instance = q1.w;
    st.key_t = uintBitsToFloat(q2.x);
    st.key_instance = q2.y;
    st.key_leaf = q2.z;
    st.status = q2.w;
    st.tri_t = uintBitsToFloat(q3.x);
    st.tri_instance = q3.y;
    st.tri_triangle = q3.z;
    st.rounds = q3.w;
    return st;
}
void nb_state_store(uint i, GpuNeuralRayState st) {
    neural_state[4u * i] = uvec4(floatBitsToUint(st.normal), floatBitsToUint(st.best_t));
    neural_state[4u * i + 1u] = uvec4(st.albedo_rg, st.albedo_b, st.hit_leaf, st.instance);
    neural_state[4u * i + 2u] = uvec4(floatBitsToUint(st.key_t), st.key_instance, st.key_leaf, st.status);
    neural_state[4u * i + 3u] = uvec4(floatBitsToUint(st.tri_t), st.tri_instance, st.tri_triangle, st.rounds);
}

// Slot k of half `half_` of the pending queue (each half holds the larger of the two round sizes'
// pairs per ray, in its own binding: half 1's slots start at the half size).
uint nb_nl_half_size() {
    return ray_capacity() * max(neural_params.leaves_per_round, neural_params.leaves_per_round_camera);
}
uint nb_nl_pending_index(uint half_, uint k) { return half_ * nb_nl_half_size() + k; }
// A pending pair as the passes use it (stored as shared/wavefront_gpu.h GpuPendingLeaf: `ray` and
// `group` packed in one word, the record 3 uvec4 of the pending bindings).
struct NbPendingPair {
    uint ray;       // path-ray slot, or ray capacity + shadow-ray slot
    uint instance;
    uint leaf;
    float t_enter;
    float t_exit;
    uint group;     // count (the group's first pair; 0 for the others) | NB_RAY_BACKFACE_BIT
    float t;        // queued: the ray's bound; answered: the hit (NB_INF: none)
    vec3 a;         // queued: world origin; answered: normal
    vec3 b;         // queued: world direction; answered: albedo
};
uvec4 nb_pending_word(uint slot, uint w) {
    uint hs = nb_nl_half_size();
    if (slot < hs) return pending_leaves[3u * slot + w];
    return pending_leaves_1[3u * (slot - hs) + w];
}
void nb_pending_set_word(uint slot, uint w, uvec4 v) {
    uint hs = nb_nl_half_size();
    if (slot < hs)
        pending_leaves[3u * slot + w] = v;
    else
        pending_leaves_1[3u * (slot - hs) + w] = v;
}
NbPendingPair nb_pending_load(uint slot) {
    uvec4 q0 = nb_pending_word(slot, 0u), q1 = nb_pending_word(slot, 1u), q2 = nb_pending_word(slot, 2u);
    NbPendingPair pl;
    pl.ray = nb_pair_ray(q0.x);
    pl.group = nb_pair_flagged_group(q0.x);
    pl.instance = q0.y;
    pl.leaf = q0.z;
    pl.t_enter = uintBitsToFloat(q0.w);
    pl.t_exit = uintBitsToFloat(q1.x);
    pl.t = uintBitsToFloat(q1.y);
    pl.a = uintBitsToFloat(uvec3(q1.zw, q2.x));
    pl.b = uintBitsToFloat(q2.yzw);
    return pl;
}
void nb_pending_store(uint slot, NbPendingPair pl) {
    nb_pending_set_word(slot, 0u, uvec4(nb_pair_pack_ray_group(pl.ray, pl.group), pl.instance, pl.leaf,
                                        floatBitsToUint(pl.t_enter)));
    nb_pending_set_word(slot, 1u, uvec4(floatBitsToUint(pl.t_exit), floatBitsToUint(pl.t), floatBitsToUint(pl.a.xy)));
    nb_pending_set_word(slot, 2u, uvec4(floatBitsToUint(pl.a.z), floatBitsToUint(pl.b)));
}
// The query pass's result of a pair. A miss (t NB_INF) stores t only: the resumed traversal takes a
// pair's normal and albedo only from a hit in front of its best one (nb_nl_take_hit).
void nb_pending_set_hit(uint slot, float t, vec3 normal, vec3 albedo) {
    uint hs = nb_nl_half_size();
    bool hit = t < NB_INF;
    uint i = 3u * (slot < hs ? slot : slot - hs);
    if (slot < hs) {
        if (hit) {
            pending_leaves[i + 1u].yzw = floatBitsToUint(vec3(t, normal.xy));
            pending_leaves[i + 2u] = floatBitsToUint(vec4(normal.z, albedo));
        } else {
            pending_leaves[i + 1u].y = floatBitsToUint(t);
        }
    } else {
        if (hit) {
            pending_leaves_1[i + 1u].yzw = floatBitsToUint(vec3(t, normal.xy));
            pending_leaves_1[i + 2u] = floatBitsToUint(vec4(normal.z, albedo));
        } else {
            pending_leaves_1[i + 1u].y = floatBitsToUint(t);
        }
    }
}

#endif
