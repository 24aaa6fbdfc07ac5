// The split query's gather pass (shared/neural_gpu.h NB_SPLIT_*): the hash-grid features of the 3
// segment points of each of the round's first split_chunk pairs, stored as 24 fp16 quads for
// passes/neural_query_mlp32.comp. Without the MLP this kernel needs few registers, so many more
// subgroups per SM hide the gathers' latency than in the fused pass (H200: results/neural/README.md).
#version 460
#define NB_COOP_ACC_BITS 32 // the paired-lane gather of lib/neural_grid.glsl
#define NB_SPLIT_FEATURES 1
#define NB_SPLIT_FEATURES_ACCESS writeonly
#include "lib/bindings.glsl"
#include "lib/neural_bindings.glsl"
#include "lib/neural_grid.glsl"
#include "lib/neural_query_pass.glsl"

layout(local_size_x = NB_NEURAL_GROUP) in;

// The workgroups of chunk (pc.mode >> NB_QUERY_CHUNK_SHIFT) of the split pairs (neural_args: all of them
// in chunk 0 where split_chunks is 1); a grid smaller than the chunk loops over it (the pipelined pass
// caps it), its condition uniform over the workgroup.
void main() {
    uint per = neural_counters.split_chunk_groups;
    uint first = ((pc.mode >> NB_QUERY_CHUNK_SHIFT) & (NB_SPLIT_MAX_CHUNKS - 1u)) * per;
    uint end = min(first + per, neural_counters.split_dispatch.x);
    for (uint g = first + gl_WorkGroupID.x; g < end; g += gl_NumWorkGroups.x) {
        uint pair = g * NB_NEURAL_GROUP + gl_LocalInvocationID.x;
        NbPendingQuery r = nb_load_pending(pair);
        vec3 p0, p1, p2;
        nb_segment_points(neural_params.box, r.org, r.dir, r.pl.t_enter, r.pl.t_exit, p0, p1, p2);
        // Every lane gathers (the lane pairs shuffle), only valid pairs store.
        NB_SPLIT_GATHER_STORE(pair, r.valid, p0, p1, p2)
    }
}
