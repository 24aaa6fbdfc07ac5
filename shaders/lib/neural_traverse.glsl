// The neural leaf kind of the two-level traversal (issue 4; included by lib/traverse.glsl before its
// TLAS leaf handler). A ray entering a neural instance (through the TLAS, in the instance's object
// space, so instancing works) walks the instance's N-BVH nearest-first:
//   closest-hit rays (path rays) look for the NEXT leaf to query: the smallest ordering key
//     (max(t_entry, tmin), instance, leaf) above the last queried one whose entry is still in front of
//     the best hit; passes/neural_traverse.comp queues it and passes/neural_query_*.comp evaluates it;
//   any-hit rays (shadow rays) query each leaf inline with the scalar network and stop at the first
//     visible, accepted hit in (tmin, tmax).
// Leaf intervals: shared/neural_gpu.h nb_neural_leaf_interval (dilated box, tmin = -inf).
#ifndef NB_NEURAL_TRAVERSE_GLSL
#define NB_NEURAL_TRAVERSE_GLSL
#include "lib/neural_bindings.glsl"
#include "lib/neural_grid.glsl"
#include "lib/neural_mlp_scalar.glsl"

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
        if (g_any_hit) {
            // Shadow ray: inline query (scalar path), any visible accepted hit in (tmin, tmax) occludes.
            if (key > g_tmax) continue;
            vec3 p0, p1, p2;
            nb_segment_points(neural_params.box, g_obj_org, g_obj_dir, te, tx, p0, p1, p2);
            float y[NB_MLP_OUTPUTS];
            nb_neural_forward_scalar(p0, p1, p2, y);
            GpuNeuralHit h = nb_neural_decode(neural_params.box, y, te, tx, neural_params.threshold);
            if ((h.flags & (NB_NEURAL_VISIBLE | NB_NEURAL_ACCEPTED)) == (NB_NEURAL_VISIBLE | NB_NEURAL_ACCEPTED) &&
                h.t > g_tmin && h.t < g_tmax) {
                g_tmax = h.t;
                g_hit_instance = g_nl_inst;
                g_hit_triangle = NB_NEURAL_TRIANGLE;
                g_done = true;
                return;
            }
            continue;
        }
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
    if (!g_any_hit) g_tmax = min(g_tmax, g_nl_cand_t);
    NB_TRAVERSE_BVH(nbvh_nodes, g_nl_root, g_obj_org, g_nl_inv_dir, nb_neural_leaf)
    if (!g_any_hit) g_tmax = saved_tmax;
}

#endif
