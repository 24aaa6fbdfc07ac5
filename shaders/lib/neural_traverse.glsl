// The neural leaf kind of the two-level traversal (issue 4; included by lib/traverse.glsl before its
// TLAS leaf handler). A ray entering a neural instance (through the TLAS, in the instance's object
// space, so instancing works) walks the instance's N-BVH nearest-first:
//   closest-hit rays (path rays) look for the NEXT leaves to query: the leaves_per_round smallest
//     ordering keys (max(t_entry, tmin), instance, leaf) above the last queried one whose entry is still
//     in front of the best hit; passes/neural_traverse.comp queues them (one traversal for several leaf
//     visits) and passes/neural_query_*.comp evaluates them; the resumed traversal applies their hits
//     in key order, so the closest accepted hit wins as with one leaf per round (a leaf's hit lies at
//     or behind its key: the extra, speculative leaves behind the best hit cannot change it);
//   shadow rays do the same (passes/neural_shadow.comp) after their triangle any-hit test: the leaf
//     queue serves both, so shadow queries are batched through the same query kernels.
// Leaf intervals: shared/neural_gpu.h nb_neural_leaf_interval (dilated box, tmin = -inf).
#ifndef NB_NEURAL_TRAVERSE_GLSL
#define NB_NEURAL_TRAVERSE_GLSL
#include "lib/neural_bindings.glsl"
#include "shared/neural_occupancy.h"

bool g_nl_skip_triangles = false; // resumed rounds: the triangle hit of round 0 is already known
bool g_nl_skip_neural = false;    // shadow rays' first round: the triangles' any-hit walk alone
uint g_nl_lod = 0u;               // N-BVH cut (LoD) of this ray
float g_nl_last_t = -NB_INF;      // last queued key (exclusive lower bound)
uint g_nl_last_inst = 0u;
uint g_nl_last_leaf = 0u;
// The g_nl_want smallest keys above the last queued one, sorted (g_nl_cand_n of them so far).
uint g_nl_want = 1u;
// The ray's leaf budget and round size (nb_nl_set_class), set by each pass before its first traversal.
uint g_nl_budget = 1u;
uint g_nl_per_round = 1u;
// Set when the ray was found truncated by its leaf budget (a leaf left in front of its best hit).
bool g_nl_truncated = false;
// Shadow rays whose truncation may occlude them (--neural-truncated-shadows block or P > 0): a round
// that spends the budget looks for one leaf more (nb_nl_want), whose key decides whether the ray is
// truncated.
bool g_nl_probe = false;
uint g_nl_cand_n = 0u;
float g_nl_cand_t[NB_NL_MAX_LEAVES_PER_ROUND];
uint g_nl_cand_inst[NB_NL_MAX_LEAVES_PER_ROUND];
uint g_nl_cand_leaf[NB_NL_MAX_LEAVES_PER_ROUND];
float g_nl_cand_entry[NB_NL_MAX_LEAVES_PER_ROUND];
float g_nl_cand_exit[NB_NL_MAX_LEAVES_PER_ROUND];
uint g_nl_inst = 0u;              // instance being walked
float g_nl_walk_tmax = NB_INF;    // the ray's limit (best hit) during a walk; g_tmax culls the walk's nodes
float g_nl_ray_tmin = 0.0f;       // the ray's tmin during a walk; g_tmin culls the walk's nodes
vec3 g_nl_inv_dir;

bool nb_nl_key_less(float ta, uint ia, uint la, float tb, uint ib, uint lb) {
    if (ta != tb) return ta < tb;
    if (ia != ib) return ia < ib;
    return la < lb;
}

// Key of the worst kept candidate while the list is full (else +inf): the bound a new one must beat.
float nb_nl_bound_t() { return g_nl_cand_n < g_nl_want ? NB_INF : g_nl_cand_t[g_nl_want - 1u]; }

// Whether the segment [t0, t1] of the ray (object space) crosses an occupied cell of `node`'s mask
// (shared/neural_occupancy.h); true where the walk is not exact. Without masks: always true.
bool nb_nl_occupied(uint node, vec3 lo, vec3 hi, float t0, float t1) {
    if (neural_params.occupancy == 0u) return true;
    GpuOccWalk w = nb_occ_walk_begin(g_obj_org, g_obj_dir, lo, hi, t0, t1);
    if (!w.exact) return true;
    uint base = neural_params.occupancy + node * NB_OCC_WORDS;
    do {
        uint bit = nb_occ_walk_bit(w);
        if (nb_occ_is_set(nbvh_bounds_words[base + (bit >> 5u)], bit)) return true;
    } while (nb_occ_walk_next(w));
    return false;
}

void nb_neural_leaf(uint first, uint count) {
    for (uint k = 0u; k < count; ++k) {
        uint node = first + k;
        float te, tx;
        vec3 lo = nbvh_bounds[2u * node].xyz, hi = nbvh_bounds[2u * node + 1u].xyz;
        if (!nb_neural_leaf_interval(g_obj_org, g_nl_inv_dir, lo, hi, te, tx)) continue;
        if (!(tx > g_nl_ray_tmin)) continue; // the leaf lies behind the ray's start
        float key = max(te, g_nl_ray_tmin);
        if (!(key < g_nl_walk_tmax)) continue;
        if (!nb_nl_key_less(g_nl_last_t, g_nl_last_inst, g_nl_last_leaf, key, g_nl_inst, node)) continue;
        if (g_nl_cand_n == g_nl_want) {
            uint w = g_nl_want - 1u;
            if (!nb_nl_key_less(key, g_nl_inst, node, g_nl_cand_t[w], g_nl_cand_inst[w], g_nl_cand_leaf[w])) continue;
        }
        // Only empty cells between the key and the exit: no true hit in this leaf (the part before the
        // key, behind tmin, holds no accepted hit either). Skipped, not queued.
        if (!nb_nl_occupied(node, lo, hi, key, tx)) continue;
        if (g_nl_cand_n < g_nl_want) g_nl_cand_n += 1u;
        // Insertion into the sorted list (the last entry drops out when it was full).
        uint j = g_nl_cand_n - 1u;
        while (j > 0u && nb_nl_key_less(key, g_nl_inst, node, g_nl_cand_t[j - 1u], g_nl_cand_inst[j - 1u],
                                        g_nl_cand_leaf[j - 1u])) {
            g_nl_cand_t[j] = g_nl_cand_t[j - 1u];
            g_nl_cand_inst[j] = g_nl_cand_inst[j - 1u];
            g_nl_cand_leaf[j] = g_nl_cand_leaf[j - 1u];
            g_nl_cand_entry[j] = g_nl_cand_entry[j - 1u];
            g_nl_cand_exit[j] = g_nl_cand_exit[j - 1u];
            j -= 1u;
        }
        g_nl_cand_t[j] = key;
        g_nl_cand_inst[j] = g_nl_inst;
        g_nl_cand_leaf[j] = node;
        g_nl_cand_entry[j] = te;
        g_nl_cand_exit[j] = tx;
        // A full list: no subtree entered behind its worst key can hold a better leaf (the node boxes
        // contain their dilated leaves, shared/neural_gpu.h nb_neural_cull_bounds), so the walk culls
        // by it from here on. H100: see the commit of this change.
        if (g_nl_cand_n == g_nl_want) g_tmax = min(g_tmax, g_nl_cand_t[g_nl_want - 1u]);
    }
}

void nb_traverse_neural_instance(uint instance) {
    GpuInstance inst = instances[instance];
    // A neural instance's blas_root is its asset; its world_to_object maps into the model's atlas space.
    uint root = neural_assets[inst.blas_root].roots[g_nl_lod];
    g_nl_inst = instance;
    g_cur_instance = instance;
    g_obj_org = nb_xform_point(inst.world_to_object, g_org);
    g_obj_dir = nb_xform_vector(inst.world_to_object, g_dir);
    g_nl_inv_dir = nb_safe_inv_dir(g_obj_dir);
    // Cull subtrees behind the worst kept candidate while walking (narrowed as the list fills; restored
    // after: the TLAS and the triangles are culled by hits only). Leaves are tested against the hit.
    float saved_tmax = g_tmax;
    g_nl_walk_tmax = saved_tmax;
    g_tmax = min(g_tmax, nb_nl_bound_t());
    // A resumed walk also culls the subtrees the ray leaves before its last queued key: their leaves
    // exit before it (node boxes contain their dilated leaves and slab exits are monotonic in the box,
    // shared/neural_gpu.h nb_neural_cull_bounds), so every key there (<= the leaf's exit) lies below the
    // last one and was queued or skipped already. Leaves are keyed against the ray's own tmin.
    float saved_tmin = g_tmin;
    g_nl_ray_tmin = saved_tmin;
    g_tmin = max(g_tmin, g_nl_last_t);
    NB_TRAVERSE_BVH(nbvh_nodes, root, g_obj_org, g_nl_inv_dir, nb_neural_leaf)
    g_tmin = saved_tmin;
    g_tmax = saved_tmax;
}

// Pass-constant encoding of the neural passes: bits 0-1 the operation, bit 2 the half of the pending
// queue (ping-pong: a resumed traversal reads its rays from the half just queried and queues into the
// other one).
uint nb_nl_op(uint mode) { return mode & 3u; }
uint nb_nl_half(uint mode) { return (mode >> 2u) & 1u; }

// Ray classes of nb_nl_set_class: a camera ray, a ray after the first hit, a shadow ray.
#define NB_NL_CAMERA 0u
#define NB_NL_PATH 1u
#define NB_NL_SHADOW 2u

// The leaves a ray of class `ray_class` may query in all (g_nl_budget: camera rays
// neural_params.max_rounds, rays after the first hit max_rounds_secondary, shadow rays
// max_rounds_shadow) and per round (g_nl_per_round: camera rays leaves_per_round_camera, the others
// leaves_per_round).
void nb_nl_set_class(uint ray_class) {
    g_nl_budget = ray_class == NB_NL_CAMERA ? neural_params.max_rounds
                  : ray_class == NB_NL_PATH ? neural_params.max_rounds_secondary
                                            : neural_params.max_rounds_shadow;
    g_nl_per_round =
        ray_class == NB_NL_CAMERA ? neural_params.leaves_per_round_camera : neural_params.leaves_per_round;
}

// Leaves a ray's next traversal looks for: the round size, within its leaf budget (g_nl_budget). Under
// g_nl_probe a round that spends the budget looks for one leaf more (where the candidate list has
// room), never queued: whether it lies in front of the ray's end after the round's hits tells whether
// the budget truncated the ray (NB_NRAY_PENDING_CAP), without the re-traversal that would find it.
uint nb_nl_want(GpuNeuralRayState st) {
    uint left = g_nl_budget > st.rounds ? g_nl_budget - st.rounds : 0u;
    uint k = max(1u, min(min(g_nl_per_round, NB_NL_MAX_LEAVES_PER_ROUND), left));
    return g_nl_probe && k == left && k < NB_NL_MAX_LEAVES_PER_ROUND ? k + 1u : k;
}

// Queues the candidates of the last traversal in front of `limit` (within the ray's leaf budget),
// contiguously in key order, into half `half` of the pending queue; returns false when the ray is finished.
// The pairs carry the query's inputs (GpuPendingLeaf): the ray's world origin and direction, its t
// bound (path rays: tmin; shadow rays: tmax) and its back-face flag (read here, only for rays that
// queue: NB_RAY_BACKFACE_BIT of a path ray's NB_RAY_DEPTH word, of a shadow ray's NB_SHADOW_PIXEL word).
bool nb_nl_queue_candidate(uint state_index, uint half_, float limit, vec3 org, vec3 dir, float t_bound,
                           inout GpuNeuralRayState st) {
    uint found = 0u;
    while (found < g_nl_cand_n && g_nl_cand_t[found] < limit) found += 1u;
    if (found == 0u) return false;
    if (st.rounds >= g_nl_budget) { // a leaf in front of the best hit, no budget left: truncated
        g_nl_truncated = true;      // (counted in leaf_cap_rays when the budget was spent)
        return false;
    }
    uint left = g_nl_budget - st.rounds;
    uint n = min(found, left); // a leaf found beyond the budget (g_nl_probe) is not queued
    uint cap = ray_capacity();
    uint flag = (state_index >= cap ? shadow_load1(NB_SHADOW_PIXEL, state_index - cap)
                                    : ray_load1(pc.in_queue, NB_RAY_DEPTH, state_index)) & NB_RAY_BACKFACE_BIT;
    uint k = atomicAdd(counters.pending_count, n);
    for (uint j = 0u; j < n; ++j) {
        NbPendingPair pl;
        pl.ray = state_index;
        pl.instance = g_nl_cand_inst[j];
        pl.leaf = g_nl_cand_leaf[j];
        pl.t_enter = g_nl_cand_entry[j];
        pl.t_exit = g_nl_cand_exit[j];
        pl.group = (j == 0u ? n : 0u) | flag;
        pl.t = t_bound;
        pl.a = org;
        pl.b = dir;
        nb_pending_store(nb_nl_pending_index(half_, k + j), pl);
    }
    st.key_t = g_nl_cand_t[n - 1u];
    st.key_instance = g_nl_cand_inst[n - 1u];
    st.key_leaf = g_nl_cand_leaf[n - 1u];
    // Fewer than g_nl_want found: the candidate list was not full (no leaf in front of the limit was
    // left out) or a candidate lay behind the limit (so do all later ones). Either way no leaf remains.
    bool last = found < g_nl_want;
    st.status = last ? NB_NRAY_PENDING_LAST : NB_NRAY_PENDING;
    if (n == left) { // the group spends the ray's budget: counted in leaf_cap_rays (the budget may cut it)
        atomicAdd(neural_counters.leaf_cap_rays, 1u);
        if (found > n) { // g_nl_probe: a leaf found beyond the budget, its key decides after the hits
            st.status = NB_NRAY_PENDING_CAP;
            st.key_t = g_nl_cand_t[n];
        } else if (!g_nl_probe) {
            // Nothing to decide: the resumed round finishes the ray (a leaf left in front of its best
            // hit is passed). Under g_nl_probe with no room to look further (a round of
            // NB_NL_MAX_LEAVES_PER_ROUND leaves) the ray is resumed once more to find one.
            st.status = NB_NRAY_PENDING_LAST;
        }
    }
    st.rounds += n;
    return true;
}

// A neural hit in front of the ray's best one becomes its best hit (pairs applied in key order, so the
// first of equal hits wins, as with one leaf per round); `leaf` is the N-BVH node that answered it.
void nb_nl_take_hit(inout GpuNeuralRayState st, float t, vec3 normal, vec3 albedo, uint instance, uint leaf) {
    if (t < st.best_t) {
        st.best_t = t;
        st.normal = normal;
        st.albedo_rg = packHalf2x16(albedo.rg);
        st.albedo_b = packHalf2x16(vec2(albedo.b, 0.0f));
        st.hit_leaf = leaf;
        st.instance = instance;
    }
}

// Whether a leaf can remain in front of `limit` after the ray's last queued key: the leaves not yet
// queued have keys above (key_t, key_instance, key_leaf), so entry distances >= key_t, and a leaf is
// queued only when its key lies in front of the limit. When the best hit is at or before key_t, the
// re-traversal would find nothing: the ray is finished without it (same decisions, same image).
bool nb_nl_may_have_more(GpuNeuralRayState st, float limit) { return st.key_t < limit; }

bool nb_nl_is_pending(uint status) {
    return status == NB_NRAY_PENDING || status == NB_NRAY_PENDING_LAST || status == NB_NRAY_PENDING_CAP;
}

// The resumed traversal of a ray: the results of its `group` pairs from pending slot `slot` on.
void nb_nl_reduce_group(uint slot, uint group, inout GpuNeuralRayState st) {
    for (uint j = 0u; j < group; ++j) {
        NbPendingPair pl = nb_pending_load(slot + j);
        nb_nl_take_hit(st, pl.t, pl.a, pl.b, pl.instance, pl.leaf); // the answered pair
    }
    st.status = NB_NRAY_TRACE;
}

void nb_nl_begin(GpuNeuralRayState st, uint lod, uint want) {
    g_nl_lod = min(lod, NB_NEURAL_MAX_LODS - 1u);
    g_nl_last_t = st.key_t;
    g_nl_last_inst = st.key_instance;
    g_nl_last_leaf = st.key_leaf;
    g_nl_want = want;
    g_nl_cand_n = 0u;
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

// Whether shadow ray `ray` (its index in the shadow queue), truncated by its leaf budget, is occluded:
// with probability truncated_shadows_occlusion (--neural-truncated-shadows: block 1, pass 0, or P), drawn
// from a hash of its pixel, sample and bounce (as its alpha-test seed, decorrelated), so that every pass
// that decides it (neural_shadow's rounds, neural_tail) draws the same: the blended-alpha rule of
// shared/scene_gpu.h nb_alpha_covers with alpha P. The leaf left in front of the ray holds occupied
// cells along it (a candidate passed the occupancy walk).
bool nb_nl_truncated_shadow_occluded(uint ray) {
    float p = neural_params.truncated_shadows_occlusion;
    if (p >= 1.0f) return true; // block (the default): no draw
    uint seed = nb_shadow_alpha_seed(shadow_load1(NB_SHADOW_PIXEL, ray) & ~NB_RAY_BACKFACE_BIT);
    return nb_alpha_covers(NB_ALPHA_BLEND, p, 0.0f, nb_pcg_hash(seed ^ 0x5bd1e995u));
}
bool nb_nl_shadow_blocked(uint ray) { return g_nl_truncated && g_nl_probe && nb_nl_truncated_shadow_occluded(ray); }

GpuNeuralRayState nb_nl_fresh_state() {
    GpuNeuralRayState st;
    st.normal = vec3(0.0f, 0.0f, 1.0f);
    st.best_t = NB_INF;
    st.albedo_rg = 0u;
    st.albedo_b = 0u;
    st.hit_leaf = 0u;
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
