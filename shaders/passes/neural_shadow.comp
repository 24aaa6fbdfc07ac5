// Neural visibility of shadow rays (hybrid renders), before passes/shadow.comp: the same ordered leaf
// search and batched queries as path rays (passes/neural_traverse.comp), with any-hit semantics. The
// state of shadow ray i lives at neural state slot capacity + i while its leaves are queried; the decision
// "occluded" goes to the ray's own NB_SHADOW_TMAX word (nb_shadow_mark_occluded), which shadow.comp
// reads anyway: a ray found unoccluded stores nothing.
//   op 0: every shadow ray: triangle any-hit (occluded -> done), else queue the first neural leaf;
//   op 1: the rays of the pairs just queried (first pair of each ray's group): any accepted hit of the
//         group -> occluded, done; the group was the ray's last or spent its budget -> not occluded,
//         done; else queue the next leaves.
// shadow.comp then reads the result instead of tracing.
#version 460
#include "lib/bindings.glsl"
#include "lib/traverse.glsl"

layout(local_size_x = NB_WAVEFRONT_GROUP) in;

void main() {
    uint op = nb_nl_op(pc.mode);
    uint half_ = nb_nl_half(pc.mode);
    uint cap = ray_capacity();
    nb_nl_set_class(NB_NL_SHADOW);
    g_nl_probe = neural_params.truncated_shadows_occlusion > 0.0f;
    uint i;
    GpuNeuralRayState st;
    if (op == 1u) {
        uint k = gl_GlobalInvocationID.x;
        if (k >= neural_counters.pending_active) return;
        uint slot = nb_nl_pending_index(half_ ^ 1u, k);
        NbPendingPair pl = nb_pending_load(slot);
        if (nb_pair_group(pl.group) == 0u) return; // the first pair of the ray's group resumes it
        i = pl.ray - cap;
        st = nb_state_load(cap + i);
        if (!nb_nl_is_pending(st.status)) return;
        bool last = st.status == NB_NRAY_PENDING_LAST;
        bool capped = st.status == NB_NRAY_PENDING_CAP;
        nb_nl_reduce_group(slot, nb_pair_group(pl.group), st);
        float tmax = uintBitsToFloat(shadow_load1(NB_SHADOW_TMAX, pl.ray - cap));
        // The leaf found beyond the budget in front of the ray's end: truncated, occluded by that leaf.
        bool blocked = capped && nb_nl_may_have_more(st, tmax) && nb_nl_truncated_shadow_occluded(i);
        // An occluder found, no leaf left (also when the last key lies at or beyond the shadow ray's
        // end) or the budget spent: done without re-traversal.
        if (last || capped || st.best_t < NB_INF || !nb_nl_may_have_more(st, tmax)) {
            st.status = NB_NRAY_DONE;
            nb_state_store(cap + i, st);
            if (st.best_t < NB_INF || blocked) nb_shadow_mark_occluded(i);
            return;
        }
    } else {
        i = gl_GlobalInvocationID.x;
        if (i >= counters.shadow_count) return;
        if ((pc.mode & NB_NL_MODE_SORTED) != 0u) i = rs_order[cap + i]; // passes/ray_sort.comp
        st = nb_nl_fresh_state();
    }
    vec3 org = shadow_load3(NB_SHADOW_ORIGIN, i);
    vec3 dir = shadow_load3(NB_SHADOW_DIR, i);
    float tmax = uintBitsToFloat(shadow_load1(NB_SHADOW_TMAX, i));
    g_alpha_seed = nb_shadow_alpha_seed(shadow_load1(NB_SHADOW_PIXEL, i) & ~NB_RAY_BACKFACE_BIT);
    nb_nl_begin(st, neural_params.lod_secondary, nb_nl_want(st));
    // Triangles first: a ray they occlude walks no N-BVH (in one walk, an N-BVH the TLAS reaches before
    // the occluding triangles was walked for nothing). Then the neural instances alone. Measured, and
    // why path rays keep one walk: engine/render/NEURAL.md.
    if (op == 0u) {
        g_nl_skip_triangles = false;
        g_nl_skip_neural = true;
        nb_trace(org, dir, 0.0f, tmax, true);
        g_nl_skip_neural = false;
        if (g_hit_instance != NB_NO_HIT) {
            nb_shadow_mark_occluded(i);
            return;
        }
    }
    g_nl_skip_triangles = true;
    nb_trace(org, dir, 0.0f, tmax, true);
    if (!nb_nl_queue_candidate(cap + i, half_, tmax, org, dir, tmax, st)) {
        // No leaf in front of tmax: not occluded. A ray decided by its first traversal stores nothing
        // (op 1 and the tail read only the states of rays with queued pairs).
        if (nb_nl_shadow_blocked(i)) nb_shadow_mark_occluded(i);
        if (op == 0u) return;
        st.status = NB_NRAY_DONE;
    }
    nb_state_store(cap + i, st);
}
