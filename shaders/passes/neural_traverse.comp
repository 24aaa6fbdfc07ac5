// Neural traversal rounds of path-ray queue pc.in_queue (replaces passes/traverse.comp when the scene
// has neural instances; engine/render/neural_stage.h records the loop). Operation nb_nl_op(pc.mode):
//   0: every ray of the queue: full traversal; stores the closest triangle hit in the hit SOA and
//      queues the first neural leaves in front of it (pending half 0);
//   1: the rays of the pairs just queried (pending half nb_nl_half(pc.mode) ^ 1, dispatched indirectly
//      over them; the first pair of each ray's group): apply the group's hits in key order, re-traverse
//      the neural instances only (triangles are known), culled by min(triangle hit, best neural hit),
//      and queue the next leaves into half nb_nl_half(pc.mode) (a ray whose group was its last,
//      NB_NRAY_PENDING_LAST, is finished without re-traversal).
// A ray is finished when no leaf key remains in front of its best hit; then a closer neural hit
// replaces the triangle hit in the hit SOA (triangle word NB_NEURAL_TRIANGLE). Every ray is finished by
// op 0, an op 1 or passes/neural_tail.comp (the rays of the pairs the last round queued): shade reads
// the hit SOA next.
#version 460
#include "lib/bindings.glsl"
#include "lib/traverse.glsl"

layout(local_size_x = NB_WAVEFRONT_GROUP) in;

void main() {
    uint op = nb_nl_op(pc.mode);
    uint half_ = nb_nl_half(pc.mode);
    uint q = pc.in_queue;
    nb_nl_set_class(pc.depth == 0u ? NB_NL_CAMERA : NB_NL_PATH);
    uint i;
    GpuNeuralRayState st;
    if (op == 1u) {
        uint k = gl_GlobalInvocationID.x;
        if (k >= neural_counters.pending_active) return;
        uint slot = nb_nl_pending_index(half_ ^ 1u, k);
        NbPendingPair pl = nb_pending_load(slot);
        if (nb_pair_group(pl.group) == 0u) return; // the first pair of the ray's group resumes it
        i = pl.ray;
        st = nb_state_load(i);
        if (!nb_nl_is_pending(st.status)) return;
        bool last = st.status == NB_NRAY_PENDING_LAST;
        nb_nl_reduce_group(slot, nb_pair_group(pl.group), st);
        // Nothing left in front, or the budget spent: no re-traversal.
        if (last || !nb_nl_may_have_more(st, min(st.tri_t, st.best_t))) {
            nb_nl_finish_path(i, st);
            nb_state_store(i, st);
            return;
        }
    } else {
        i = gl_GlobalInvocationID.x;
        if (i >= queue_count(q)) return;
        if ((pc.mode & NB_NL_MODE_SORTED) != 0u) i = rs_order[i]; // passes/ray_sort.comp
        st = nb_nl_fresh_state();
    }
    vec3 org = ray_load3(q, NB_RAY_ORIGIN, i);
    vec3 dir = ray_load3(q, NB_RAY_DIR, i);
    g_alpha_seed = ray_load1(q, NB_RAY_RNG, i);
    float t_resume = uintBitsToFloat(ray_load1(q, NB_RAY_T_RESUME, i));
    nb_nl_begin(st, pc.depth == 0u ? neural_params.lod_primary : neural_params.lod_secondary, nb_nl_want(st));
    if (op == 0u) {
        g_nl_skip_triangles = false;
        g_camera_ray = pc.depth == 0u; // outline shells (NB_INSTANCE_CAMERA_ONLY) are seen by camera rays only
        nb_trace(org, dir, t_resume, NB_INF, false);
        st.tri_t = g_hit_instance == NB_NO_HIT ? NB_INF : g_tmax;
        st.tri_instance = g_hit_instance;
        st.tri_triangle = g_hit_triangle;
        hit_store1(NB_HIT_T, i, floatBitsToUint(st.tri_t));
        hit_store1(NB_HIT_INSTANCE, i, g_hit_instance);
        hit_store1(NB_HIT_TRIANGLE, i, g_hit_triangle);
        hit_store_bary(i, g_hit_bary);
    } else {
        g_nl_skip_triangles = true;
        nb_trace(org, dir, t_resume, min(st.tri_t, st.best_t), false);
    }
    if (!nb_nl_queue_candidate(i, half_, min(st.tri_t, st.best_t), org, dir, t_resume, st)) {
        // A ray finished by its first traversal has no neural hit (the hit SOA holds what it traced) and
        // nothing reads its state (neural_surface.glsl reads neural hits only, op 1 and the tail the rays
        // of queued pairs): nothing is stored (every camera ray of the wave passes here).
        if (op == 0u) return;
        nb_nl_finish_path(i, st);
    }
    nb_state_store(i, st);
}
