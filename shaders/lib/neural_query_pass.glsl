// Neural query pass of the wavefront loop (passes/neural_query_*.comp): one batched dispatch over the
// queued (ray, leaf) pairs. Each pair: the ray in the instance's object space, the 3-point encoding of
// its leaf segment (reversed when the origin is inside the leaf), the network, the decode; a visible,
// accepted hit in front of the ray's start and of its best hit so far becomes its best hit (normal in
// world space). The ray then goes back to traversal (next leaf) in the next round.
#ifndef NB_NEURAL_QUERY_PASS_GLSL
#define NB_NEURAL_QUERY_PASS_GLSL

struct NbPendingQuery {
    bool valid;
    GpuPendingLeaf pl;
    vec3 org;  // object space
    vec3 dir;
};

NbPendingQuery nb_load_pending(uint k) {
    NbPendingQuery r;
    r.valid = k < neural_counters.pending_active;
    r.org = vec3(0.0f);
    r.dir = vec3(0.0f, 0.0f, 1.0f);
    r.pl.ray = 0u;
    r.pl.instance = 0u;
    r.pl.leaf = 0u;
    r.pl.t_enter = 0.0f;
    r.pl.t_exit = 0.0f;
    if (!r.valid) return r;
    r.pl = pending_leaves[k];
    GpuInstance inst = instances[r.pl.instance];
    r.org = nb_xform_point(inst.world_to_object, ray_load3(pc.in_queue, NB_RAY_ORIGIN, r.pl.ray));
    r.dir = nb_xform_vector(inst.world_to_object, ray_load3(pc.in_queue, NB_RAY_DIR, r.pl.ray));
    return r;
}

void nb_apply_neural_result(NbPendingQuery r, float y[NB_MLP_OUTPUTS]) {
    GpuNeuralHit h = nb_neural_decode(neural_params.box, y, r.pl.t_enter, r.pl.t_exit, neural_params.threshold);
    uint ray = r.pl.ray;
    GpuNeuralRayState st = neural_state[ray];
    float tmin = uintBitsToFloat(ray_load1(pc.in_queue, NB_RAY_T_RESUME, ray));
    if ((h.flags & (NB_NEURAL_VISIBLE | NB_NEURAL_ACCEPTED)) == (NB_NEURAL_VISIBLE | NB_NEURAL_ACCEPTED) &&
        h.t > tmin && h.t < st.best_t) {
        st.best_t = h.t;
        vec3 n = nb_xform_normal(instances[r.pl.instance].world_to_object, h.normal);
        float len = length(n);
        st.normal = len > 0.0f ? n / len : vec3(0.0f, 0.0f, 1.0f);
        st.albedo = h.albedo;
        st.instance = r.pl.instance;
    }
    st.status = NB_NRAY_TRACE; // one pair per ray per round: no write races
    neural_state[ray] = st;
}

#endif
