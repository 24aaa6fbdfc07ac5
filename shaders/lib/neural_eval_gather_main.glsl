// Body of passes/neural_eval_gather.comp, the flat-list form of the split query's gather pass
// (passes/neural_gather.comp): the hash-grid features of each query's 3 segment points, written as 24
// fp16 quads (point-major, then level) to the features buffer as its tile rows (shared/neural_gpu.h);
// passes/neural_eval_mlp32.comp runs the MLP on them. For the benchmark and tests.
#define NB_COOP_ACC_BITS 32 // the paired-lane gather of lib/neural_grid.glsl
#define NB_GATHER_YPAIR 1 // the y-pair loads of the dense levels (lib/neural_grid.glsl)
#include "lib/neural_eval_common.glsl"
layout(set = 0, binding = NB_NEVAL_BIND_FEATURES, std430) writeonly buffer FeatureTiles { uvec4 split_feature_tiles[]; };
#include "lib/neural_grid.glsl"

layout(local_size_x = NB_NEURAL_GROUP) in;

// Queries [pc.first, pc.count). A grid of fewer workgroups than the range needs loops over it (the
// pipelined split query of NeuralEvaluator caps the gather's residency so that the previous chunk's MLP
// kernel runs beside it); the loop's condition is uniform over the workgroup (shuffles need every lane).
void main() {
    for (uint base = pc.first + gl_WorkGroupID.x * NB_NEURAL_GROUP; base < pc.count;
         base += gl_NumWorkGroups.x * NB_NEURAL_GROUP) {
        uint i = base + gl_LocalInvocationID.x;
        bool valid = i < pc.count;
        GpuNeuralQuery q = nb_eval_query(i, valid);
        vec3 p0, p1, p2;
        nb_segment_points(pc.box, q.origin, q.dir, q.t_entry, q.t_exit, p0, p1, p2);
        NB_SPLIT_GATHER_STORE(i, valid, p0, p1, p2)
    }
}
