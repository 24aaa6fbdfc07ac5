// The tail of a neural loop (path or shadow rays): after a few batched rounds only a few rays still
// have leaves to visit, and each further round would cost three dependent dispatches for them. This
// pass takes the pairs queued by the last batched round (pending half nb_nl_half(pc.mode)) and finishes
// each ray in one invocation (the first pair of its group): the group's queries (scalar network), then
// re-traverse the neural instances for the next leaf, query, ... until no leaf is left in front of its
// best hit or its leaf budget is spent. Same decisions as the batched rounds (same ordering keys, same
// decode), without the round trips.
#version 460
#include "lib/bindings.glsl"
#include "lib/traverse.glsl"
#include "lib/neural_grid.glsl"
#include "lib/neural_mlp_scalar.glsl"
#include "lib/neural_query_pass.glsl"

layout(local_size_x = NB_WAVEFRONT_GROUP) in;

// Query of one pair with the scalar network: its accepted hit (NB_INF: none).
float nb_tail_query(NbPendingQuery r, out vec3 normal, out vec3 albedo) {
    vec3 p0, p1, p2;
    nb_segment_points(neural_params.box, r.org, r.dir, r.pl.t_enter, r.pl.t_exit, p0, p1, p2);
    float y[NB_MLP_OUTPUTS];
    nb_neural_forward_scalar(p0, p1, p2, y);
    return nb_neural_pair_hit(r, y, normal, albedo);
}

void main() {
    NbPendingQuery r = nb_load_pending(gl_GlobalInvocationID.x);
    if (!r.valid || nb_pair_group(r.pl.group) == 0u) return; // the first pair of each ray's group finishes the ray
    uint cap = ray_capacity();
    uint ray = r.pl.ray;
    bool shadow = ray >= cap;
    uint i = shadow ? ray - cap : ray;
    vec3 org = shadow ? shadow_load3(NB_SHADOW_ORIGIN, i) : ray_load3(pc.in_queue, NB_RAY_ORIGIN, i);
    vec3 dir = shadow ? shadow_load3(NB_SHADOW_DIR, i) : ray_load3(pc.in_queue, NB_RAY_DIR, i);
    float tmin = shadow ? 0.0f : uintBitsToFloat(ray_load1(pc.in_queue, NB_RAY_T_RESUME, i));
    float tmax = shadow ? uintBitsToFloat(shadow_load1(NB_SHADOW_TMAX, i)) : NB_INF;
    g_alpha_seed = shadow ? nb_shadow_alpha_seed(shadow_load1(NB_SHADOW_PIXEL, i) & ~NB_RAY_BACKFACE_BIT)
                          : ray_load1(pc.in_queue, NB_RAY_RNG, i);
    uint lod = (shadow || pc.depth != 0u) ? neural_params.lod_secondary : neural_params.lod_primary;
    nb_nl_set_class(shadow ? NB_NL_SHADOW : pc.depth == 0u ? NB_NL_CAMERA : NB_NL_PATH);
    g_nl_probe = shadow && neural_params.truncated_shadows_occlusion > 0.0f;
    GpuNeuralRayState st = nb_state_load(ray);
    bool last = st.status == NB_NRAY_PENDING_LAST; // no leaf left behind this group
    bool capped = st.status == NB_NRAY_PENDING_CAP; // the budget spent, the leaf beyond it at key_t
    // (a ray whose last batched group spent its budget was counted in leaf_cap_rays there)
    // The group queued by the last batched round, in key order.
    uint group = nb_pair_group(r.pl.group);
    for (uint j = 0u; j < group; ++j) {
        NbPendingQuery rj = j == 0u ? r : nb_load_pending(gl_GlobalInvocationID.x + j);
        vec3 n, a;
        float t = nb_tail_query(rj, n, a);
        nb_nl_take_hit(st, t, n, a, rj.pl.instance, rj.pl.leaf);
    }
    for (uint guard = 0u; guard <= g_nl_budget; ++guard) {
        if (shadow && st.best_t < NB_INF) { // occluded
            st.status = NB_NRAY_DONE;
            nb_state_store(ray, st);
            nb_shadow_mark_occluded(i);
            return;
        }
        float limit = shadow ? tmax : min(st.tri_t, st.best_t);
        bool found = false;
        if (capped) { // (only the first iteration) truncated when the leaf beyond lies in front
            g_nl_truncated = nb_nl_may_have_more(st, limit);
        } else if (!last && nb_nl_may_have_more(st, limit)) {
            nb_nl_begin(st, lod, 1u);
            g_nl_skip_triangles = true;
            nb_trace(org, dir, tmin, limit, shadow);
            found = g_nl_cand_n > 0u && g_nl_cand_t[0] < limit;
            if (found && st.rounds >= g_nl_budget) { // truncated by the leaf budget (counted when spent)
                g_nl_truncated = true;
                found = false;
            }
        }
        if (!found) {
            if (shadow) {
                st.status = NB_NRAY_DONE;
                if (nb_nl_shadow_blocked(i)) nb_shadow_mark_occluded(i);
            } else {
                nb_nl_finish_path(i, st);
            }
            nb_state_store(ray, st);
            return;
        }
        st.key_t = g_nl_cand_t[0];
        st.key_instance = g_nl_cand_inst[0];
        st.key_leaf = g_nl_cand_leaf[0];
        st.rounds += 1u;
        // The next query (the first ones were counted by neural_args); the one that wraps carries.
        if (atomicAdd(neural_counters.queries_total, 1u) == 0xFFFFFFFFu) atomicAdd(neural_counters.queries_total_hi, 1u);
        atomicAdd(neural_counters.queries_by_depth[min(pc.depth, NB_STAT_DEPTHS - 1u)], 1u);
        r.pl.instance = g_nl_cand_inst[0];
        r.pl.leaf = g_nl_cand_leaf[0];
        r.pl.t_enter = g_nl_cand_entry[0];
        r.pl.t_exit = g_nl_cand_exit[0];
        GpuInstance inst = instances[r.pl.instance];
        r.org = nb_xform_point(inst.world_to_object, org);
        r.dir = nb_xform_vector(inst.world_to_object, dir);
        vec3 n, a;
        float t = nb_tail_query(r, n, a);
        nb_nl_take_hit(st, t, n, a, r.pl.instance, r.pl.leaf);
        if (st.rounds == g_nl_budget) { // the budget spent (as in nb_nl_queue_candidate)
            atomicAdd(neural_counters.leaf_cap_rays, 1u);
            last = !g_nl_probe; // else one more traversal tells whether a leaf is left (truncated)
        }
    }
    // Not reached: each turn above spends one leaf of the budget, and the turn after the last one
    // returns. Finished here all the same, so that no ray leaves the tail undecided.
    if (shadow) {
        st.status = NB_NRAY_DONE;
        if (st.best_t < NB_INF) nb_shadow_mark_occluded(i);
    } else {
        nb_nl_finish_path(i, st);
    }
    nb_state_store(ray, st);
}
