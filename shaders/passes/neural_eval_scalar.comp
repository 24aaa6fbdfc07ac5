// Neural queries of a flat list, scalar fp16 path (lib/neural_mlp_scalar.glsl): one query per
// invocation. Runs on every Vulkan 1.2 device; makes no assumption on the subgroup size.
#version 460
// The dense levels' corners through the y-pair table (shared/hashgrid.h), as the split query's gather
// reads them: the lavapipe cross-check against the CPU reference covers the table (its contents and
// indexing), which the GPU gather kernels need a subgroup size of 32 to run.
#define NB_GATHER_YPAIR 1
#include "lib/neural_eval_common.glsl"
layout(set = 0, binding = NB_NEVAL_BIND_MLP, scalar) readonly buffer MlpBuffer { uint neural_mlp[]; };
#include "lib/neural_grid.glsl"
#include "lib/neural_mlp_scalar.glsl"

layout(local_size_x = NB_NEURAL_GROUP) in;

void main() {
    uint i = pc.first + gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    GpuNeuralQuery q = queries[i];
    vec3 p0, p1, p2;
    nb_segment_points(pc.box, q.origin, q.dir, q.t_entry, q.t_exit, p0, p1, p2);
    float y[NB_MLP_OUTPUTS];
    nb_neural_forward_scalar(p0, p1, p2, y);
    hits[i] = nb_neural_decode(pc.box, y, q.t_entry, q.t_exit, length(q.dir), pc.threshold);
}
