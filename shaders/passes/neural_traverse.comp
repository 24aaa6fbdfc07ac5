// Neural traversal rounds of path-ray queue pc.in_queue (replaces passes/traverse.comp when the scene
// has neural instances; engine/render/neural_stage.h records the loop):
//   pc.mode 0: full traversal; stores the closest triangle hit in the hit SOA and queues the first
//              neural leaf (if any lies in front of it);
//   pc.mode 1: rays whose pair was just queried re-traverse the neural instances only (triangles are
//              known), culled by min(triangle hit, best neural hit), and queue their next leaf;
//   pc.mode 2: rays still undecided after the last round keep the best hit found so far.
// A ray is finished when no leaf key remains in front of its best hit; then a closer neural hit
// replaces the triangle hit in the hit SOA (triangle word NB_NEURAL_TRIANGLE).
#version 460
#include "lib/bindings.glsl"
#include "lib/traverse.glsl"

layout(local_size_x = NB_WAVEFRONT_GROUP) in;

void finish(uint i, inout GpuNeuralRayState st) {
    st.status = NB_NRAY_DONE;
    if (st.best_t < st.tri_t) {
        hit_store1(NB_HIT_T, i, floatBitsToUint(st.best_t));
        hit_store1(NB_HIT_INSTANCE, i, st.instance);
        hit_store1(NB_HIT_TRIANGLE, i, NB_NEURAL_TRIANGLE);
    }
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    uint q = pc.in_queue;
    if (i >= queue_count(q)) return;
    GpuNeuralRayState st;
    if (pc.mode == 0u) {
        st.normal = vec3(0.0f, 0.0f, 1.0f);
        st.best_t = NB_INF;
        st.albedo = vec3(0.0f);
        st.instance = NB_NO_HIT;
        st.key_t = -NB_INF;
        st.key_instance = 0u;
        st.key_leaf = 0u;
        st.status = NB_NRAY_TRACE;
        st.rounds = 0u;
    } else {
        st = neural_state[i];
        if (st.status != NB_NRAY_TRACE) return;
        if (pc.mode == 2u) {
            finish(i, st);
            neural_state[i] = st;
            return;
        }
    }
    vec3 org = ray_load3(q, NB_RAY_ORIGIN, i);
    vec3 dir = ray_load3(q, NB_RAY_DIR, i);
    g_alpha_seed = ray_load1(q, NB_RAY_RNG, i);
    float t_resume = uintBitsToFloat(ray_load1(q, NB_RAY_T_RESUME, i));
    g_nl_root = pc.depth == 0u ? neural_params.root_primary : neural_params.root_secondary;
    g_nl_last_t = st.key_t;
    g_nl_last_inst = st.key_instance;
    g_nl_last_leaf = st.key_leaf;
    g_nl_cand_t = NB_INF;
    g_nl_cand_inst = NB_NO_HIT;
    if (pc.mode == 0u) {
        g_nl_skip_triangles = false;
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
    bool found = g_nl_cand_inst != NB_NO_HIT && g_nl_cand_t < min(st.tri_t, st.best_t);
    if (found && st.rounds < neural_params.max_rounds) {
        uint k = atomicAdd(counters.pending_count, 1u);
        GpuPendingLeaf pl;
        pl.ray = i;
        pl.instance = g_nl_cand_inst;
        pl.leaf = g_nl_cand_leaf;
        pl.t_enter = g_nl_cand_entry;
        pl.t_exit = g_nl_cand_exit;
        pending_leaves[k] = pl;
        st.key_t = g_nl_cand_t;
        st.key_instance = g_nl_cand_inst;
        st.key_leaf = g_nl_cand_leaf;
        st.status = NB_NRAY_PENDING;
        st.rounds += 1u;
    } else {
        finish(i, st);
    }
    neural_state[i] = st;
}
