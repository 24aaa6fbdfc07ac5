// Neural query pass of the wavefront loop (passes/neural_query_*.comp): one batched dispatch over the
// queued (ray, leaf) pairs. Each pair: the ray in the instance's object space, the 3-point encoding of
// its leaf segment (reversed when the origin is inside the leaf), the network, the decode; a visible,
// accepted hit in front of the ray's start is stored with the pair; the ray's resumed traversal (next
// round) keeps the closest (passes/neural_traverse.comp, neural_shadow.comp).
#ifndef NB_NEURAL_QUERY_PASS_GLSL
#define NB_NEURAL_QUERY_PASS_GLSL

struct NbPendingQuery {
    bool valid;
    uint slot; // index in pending_leaves
    NbPendingPair pl;
    vec3 org;  // object space
    vec3 dir;
};

// First pair of the round a query pass takes: 0, or for the fused pass after the split pass the pairs
// past its features buffer, or all of a small round's (NB_QUERY_MODE_OVERFLOW, shared/neural_gpu.h).
uint nb_query_first_pair() { return (pc.mode & NB_QUERY_MODE_OVERFLOW) != 0u ? neural_counters.overflow_first : 0u; }

// Pair k of pending half nb_nl_half(pc.mode) (neural_traverse.glsl). Rays >= capacity are shadow
// rays (shadow SOA index ray - capacity), the others path rays of queue pc.in_queue.
NbPendingQuery nb_load_pending(uint k) {
    NbPendingQuery r;
    r.valid = k < neural_counters.pending_active;
    r.slot = 0u;
    r.org = vec3(0.0f);
    r.dir = vec3(0.0f, 0.0f, 1.0f);
    r.pl.ray = 0u;
    r.pl.instance = 0u;
    r.pl.leaf = 0u;
    r.pl.t_enter = 0.0f;
    r.pl.t_exit = 0.0f;
    r.pl.group = 0u;
    r.pl.t = 0.0f;
    r.pl.a = vec3(0.0f);
    r.pl.b = vec3(0.0f, 0.0f, 1.0f);
    if (!r.valid) return r;
    r.slot = nb_nl_pending_index((pc.mode >> 2u) & 1u, k);
    r.pl = nb_pending_load(r.slot); // queued, not yet answered: t, a, b are the ray's bound, origin, direction
    GpuInstance inst = instances[r.pl.instance];
    r.org = nb_xform_point(inst.world_to_object, r.pl.a);
    r.dir = nb_xform_vector(inst.world_to_object, r.pl.b);
    return r;
}

// Whether a visible-or-not answer stops the ray. Alpha-blended assets (glTF BLEND): the network learned
// the probability that the leaf segment stops a ray (both trainers' visibility target,
// trainer/ground_truth.h), so the hit is taken with that probability (shared/scene_gpu.h
// nb_alpha_covers), as the classical traversal takes a blended triangle; above the threshold, a lens of
// alpha 0.3 would vanish and one of 0.7 turn opaque. Every other asset keeps the threshold
// (`thresholded`). A departure from the paper and the official code, which have no alpha. One draw per
// ray (and depth) and instance, not per leaf: N-BVH leaf boxes overlap, and every leaf whose box holds
// a crossing learned its probability, so independent draws per leaf compound (Flight Helmet's lenses
// alone, camera rays, lavapipe: transmission 0.44 with a draw per leaf, 0.70 with one per instance,
// 0.79 once the ground truth also let rays through the lenses' single-sided back faces; classical 0.79).
bool nb_neural_covers(NbPendingQuery r, bool shadow, float visibility, bool thresholded) {
    if (!NB_HAS_ALPHA_MASK) return thresholded;
    uint material = neural_assets[instances[r.pl.instance].blas_root].material;
    if (materials[material].alpha_mode != NB_ALPHA_BLEND) return thresholded;
    uint cap = ray_capacity();
    uint seed = shadow ? nb_shadow_alpha_seed(shadow_load1(NB_SHADOW_PIXEL, r.pl.ray - cap) & ~NB_RAY_BACKFACE_BIT)
                       : ray_load1(pc.in_queue, NB_RAY_RNG, r.pl.ray) ^ (pc.depth << 24u);
    uint draw = nb_pcg_hash(seed ^ nb_pcg_hash(r.pl.instance + 0x68E31DA4u));
    return nb_alpha_covers(NB_ALPHA_BLEND, visibility, 0.0f, draw);
}

// The accepted hit of a pair (t NB_INF: none): visible and accepted, in front of the ray's start and
// its tmax (shadow rays); world-space normal.
float nb_neural_pair_hit(NbPendingQuery r, float y[NB_MLP_OUTPUTS], out vec3 normal, out vec3 albedo) {
    GpuNeuralHit h = nb_neural_decode(neural_params.box, y, r.pl.t_enter, r.pl.t_exit, length(r.dir),
                                      neural_params.threshold);
    bool shadow = r.pl.ray >= ray_capacity();
    float tmin = shadow ? 0.0f : r.pl.t; // the bound the pair was queued with (GpuPendingLeaf)
    float tmax = shadow ? r.pl.t : NB_INF;
    bool flagged = (r.pl.group & NB_RAY_BACKFACE_BIT) != 0u;
    normal = vec3(0.0f, 0.0f, 1.0f);
    albedo = h.albedo;
    bool visible = (h.flags & NB_NEURAL_VISIBLE) != 0u;
    if ((h.flags & NB_NEURAL_ACCEPTED) != 0u && nb_neural_covers(r, shadow, h.visibility, visible) &&
        h.t > tmin && h.t < tmax && !nb_backface_skip(flagged, shadow, nb_query_reversed(r.pl.t_enter), h.normal, r.dir)) {
        vec3 n = nb_xform_normal(instances[r.pl.instance].world_to_object, h.normal);
        float len = length(n);
        normal = len > 0.0f ? n / len : vec3(0.0f, 0.0f, 1.0f);
        return h.t;
    }
    return NB_INF;
}

// Batched rounds: the pair's result goes to its pending slot; the ray's resumed traversal applies the
// results of its pairs in key order (several pairs of one ray per round: no shared writes here).
void nb_apply_neural_result(NbPendingQuery r, float y[NB_MLP_OUTPUTS]) {
    vec3 normal, albedo;
    float t = nb_neural_pair_hit(r, y, normal, albedo);
    nb_pending_set_hit(r.slot, t, normal, albedo);
}

#endif
