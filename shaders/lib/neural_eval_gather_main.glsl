// Body of passes/neural_eval_gather.comp, the flat-list form of the split query's gather pass
// (passes/neural_gather.comp): the hash-grid features of each query's 3 segment points, written as 24
// fp16 quads (point-major, then level) to the features buffer as its tile rows (shared/neural_gpu.h);
// passes/neural_eval_mlp32.comp runs the MLP on them. For the benchmark and tests.
#define NB_COOP_ACC_BITS 32 // the paired-lane gather of lib/neural_grid.glsl
#include "lib/neural_eval_common.glsl"
layout(set = 0, binding = NB_NEVAL_BIND_FEATURES, std430) writeonly buffer FeatureTiles { uvec4 split_feature_tiles[]; };
#include "lib/neural_grid.glsl"

layout(local_size_x = NB_NEURAL_GROUP) in;

void main() {
    uint i = gl_GlobalInvocationID.x;
    bool valid = i < pc.count;
    GpuNeuralQuery q = nb_eval_query(i, valid);
    vec3 p0, p1, p2;
    nb_segment_points(pc.box, q.origin, q.dir, q.t_entry, q.t_exit, p0, p1, p2);
    NB_SPLIT_GATHER_STORE(i, valid, p0, p1, p2)
}
