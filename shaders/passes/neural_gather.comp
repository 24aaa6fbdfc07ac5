// The split query's gather pass (shared/neural_gpu.h NB_SPLIT_*): the hash-grid features of the 3
// segment points of each of the round's first split_chunk pairs, stored as 24 fp16 quads for
// passes/neural_query_mlp32.comp. Without the MLP this kernel needs few registers, so many more
// subgroups per SM hide the gathers' latency than in the fused pass (H200: results/neural/README.md).
#version 460
#define NB_COOP_ACC_BITS 32 // the paired-lane gather of lib/neural_grid.glsl
#define NB_SPLIT_FEATURES 1
#define NB_GATHER_YPAIR 1 // the y-pair loads of the dense levels (lib/neural_grid.glsl)
#define NB_SPLIT_FEATURES_ACCESS writeonly
#include "lib/bindings.glsl"
#include "lib/neural_bindings.glsl"
#include "lib/neural_grid.glsl"
#include "lib/neural_query_pass.glsl"

layout(local_size_x = NB_NEURAL_GROUP) in;

void main() {
    uint pair = gl_GlobalInvocationID.x;
    NbPendingQuery r = nb_load_pending(pair);
    vec3 p0, p1, p2;
    nb_segment_points(neural_params.box, r.org, r.dir, r.pl.t_enter, r.pl.t_exit, p0, p1, p2);
    // Every lane gathers (the lane pairs shuffle), only valid pairs store.
    NB_SPLIT_GATHER_STORE(pair, r.valid, p0, p1, p2)
}
