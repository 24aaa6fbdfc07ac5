// The neural leaf kind of the two-level traversal (issue 4; included by lib/traverse.glsl before its
// TLAS leaf handler). A ray entering a neural instance (through the TLAS, in the instance's object
// space, so instancing works) walks the instance's N-BVH nearest-first:
//   closest-hit rays (path rays) look for the NEXT leaf to query: the smallest ordering key
//     (max(t_entry, tmin), instance, leaf) above the last queried one whose entry is still in front of
//     the best hit; passes/neural_traverse.comp queues it and passes/neural_query_*.comp evaluates it;
//   shadow rays do the same (passes/neural_shadow.comp) after their triangle any-hit test: the leaf
//     queue serves both, so shadow queries are batched through the same query kernels.
// Leaf intervals: shared/neural_gpu.h nb_neural_leaf_interval (dilated box, tmin = -inf).
#ifndef NB_NEURAL_TRAVERSE_GLSL
#define NB_NEURAL_TRAVERSE_GLSL
#include "lib/neural_bindings.glsl"

bool g_nl_skip_triangles = false; // resumed rounds: the triangle hit of round 0 is already known
uint g_nl_root = 0u;              // N-BVH cut (LoD) root of this ray
float g_nl_last_t = -NB_INF;      // last queued key (exclusive lower bound)
uint g_nl_last_inst = 0u;
uint g_nl_last_leaf = 0u;
float g_nl_cand_t = NB_INF;       // best candidate so far
uint g_nl_cand_inst = NB_NO_HIT;
uint g_nl_cand_leaf = 0u;
float g_nl_cand_entry = 0.0f;
float g_nl_cand_exit = 0.0f;
uint g_nl_inst = 0u;              // instance being walked
vec3 g_nl_inv_dir;

bool nb_nl_key_less(float ta, uint ia, uint la, float tb, uint ib, uint lb) {
    if (ta != tb) return ta < tb;
    if (ia != ib) return ia < ib;
    return la < lb;
}

void nb_neural_leaf(uint first, uint count) {
    for (uint k = 0u; k < count; ++k) {
        uint node = first + k;
        float te, tx;
        if (!nb_neural_leaf_interval(g_obj_org, g_nl_inv_dir, nbvh_bounds[2u * node], nbvh_bounds[2u * node + 1u], te, tx))
            continue;
        if (!(tx > g_tmin)) continue; // the leaf lies behind the ray's start
        float key = max(te, g_tmin);
        if (!(key < g_tmax)) continue;
        if (!nb_nl_key_less(g_nl_last_t, g_nl_last_inst, g_nl_last_leaf, key, g_nl_inst, node)) continue;
        if (!nb_nl_key_less(key, g_nl_inst, node, g_nl_cand_t, g_nl_cand_inst, g_nl_cand_leaf)) continue;
        g_nl_cand_t = key;
        g_nl_cand_inst = g_nl_inst;
        g_nl_cand_leaf = node;
        g_nl_cand_entry = te;
        g_nl_cand_exit = tx;
    }
}

void nb_traverse_neural_instance(uint instance) {
    GpuInstance inst = instances[instance];
    g_nl_inst = instance;
    g_cur_instance = instance;
    g_obj_org = nb_xform_point(inst.world_to_object, g_org);
    g_obj_dir = nb_xform_vector(inst.world_to_object, g_dir);
    g_nl_inv_dir = nb_safe_inv_dir(g_obj_dir);
    // Cull subtrees behind the current candidate while walking (restored after: the TLAS and the
    // triangles are culled by hits only).
    float saved_tmax = g_tmax;
    g_tmax = min(g_tmax, g_nl_cand_t);
    NB_TRAVERSE_BVH(nbvh_nodes, g_nl_root, g_obj_org, g_nl_inv_dir, nb_neural_leaf)
    g_tmax = saved_tmax;
}

// Pass-constant encoding of the neural passes: bits 0-1 the operation, bit 2 the half of the pending
// queue (ping-pong: a resumed traversal reads its rays from the half just queried and queues into the
// other one).
uint nb_nl_op(uint mode) { return mode & 3u; }
uint nb_nl_half(uint mode) { return (mode >> 2u) & 1u; }

// Queues the candidate of the last traversal (if any, in front of `limit`, within the ray's leaf budget)
// into half `half` of the pending queue; returns false when the ray is finished.
bool nb_nl_queue_candidate(uint state_index, uint half_, float limit, inout GpuNeuralRayState st) {
    bool found = g_nl_cand_inst != NB_NO_HIT && g_nl_cand_t < limit;
    if (!found || st.rounds >= neural_params.max_rounds) return false;
    uint k = atomicAdd(counters.pending_count, 1u);
    GpuPendingLeaf pl;
    pl.ray = state_index;
    pl.instance = g_nl_cand_inst;
    pl.leaf = g_nl_cand_leaf;
    pl.t_enter = g_nl_cand_entry;
    pl.t_exit = g_nl_cand_exit;
    pending_leaves[half_ * ray_capacity() + k] = pl;
    st.key_t = g_nl_cand_t;
    st.key_instance = g_nl_cand_inst;
    st.key_leaf = g_nl_cand_leaf;
    st.status = NB_NRAY_PENDING;
    st.rounds += 1u;
    return true;
}

void nb_nl_begin(GpuNeuralRayState st, uint root) {
    g_nl_root = root;
    g_nl_last_t = st.key_t;
    g_nl_last_inst = st.key_instance;
    g_nl_last_leaf = st.key_leaf;
    g_nl_cand_t = NB_INF;
    g_nl_cand_inst = NB_NO_HIT;
}

// A path ray with no leaf left: a neural hit closer than the triangle hit replaces it in the hit SOA.
void nb_nl_finish_path(uint i, inout GpuNeuralRayState st) {
    st.status = NB_NRAY_DONE;
    if (st.best_t < st.tri_t) {
        hit_store1(NB_HIT_T, i, floatBitsToUint(st.best_t));
        hit_store1(NB_HIT_INSTANCE, i, st.instance);
        hit_store1(NB_HIT_TRIANGLE, i, NB_NEURAL_TRIANGLE);
    }
}

GpuNeuralRayState nb_nl_fresh_state() {
    GpuNeuralRayState st;
    st.normal = vec3(0.0f, 0.0f, 1.0f);
    st.best_t = NB_INF;
    st.albedo = vec3(0.0f);
    st.instance = NB_NO_HIT;
    st.key_t = -NB_INF;
    st.key_instance = 0u;
    st.key_leaf = 0u;
    st.status = NB_NRAY_TRACE;
    st.tri_t = NB_INF;
    st.tri_instance = NB_NO_HIT;
    st.tri_triangle = 0u;
    st.rounds = 0u;
    return st;
}

#endif
