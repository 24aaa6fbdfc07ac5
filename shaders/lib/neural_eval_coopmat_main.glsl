// Body of passes/neural_eval_coop{16,32}.comp (the includer defines NB_COOP_ACC_BITS): 64 queries per
// workgroup through the fused cooperative-matrix MLP.
#include "lib/neural_eval_common.glsl"
// The workgroup's first query.
uint nb_group_first;
#define NB_SPLIT_GROUP_FIRST nb_group_first
layout(set = 0, binding = NB_NEVAL_BIND_MLP, std430) readonly buffer MlpBuffer { uvec4 neural_mlp_tiles[]; };
#ifdef NB_SPLIT_FEATURES
layout(set = 0, binding = NB_NEVAL_BIND_FEATURES, std430) readonly buffer FeatureBuffer { uvec2 split_features[]; };
layout(set = 0, binding = NB_NEVAL_BIND_FEATURES, std430) readonly buffer FeatureTiles { uvec4 split_feature_tiles[]; };
#endif
#include "lib/neural_grid.glsl"
#include "lib/neural_mlp_coopmat.glsl"

layout(local_size_x = NB_NEURAL_GROUP) in;

// Benchmark breakdown (NeuralEvaluator::set_part): 0 = full query, 1 = hash-grid features only (the MLP
// skipped, outputs read straight from the staged features), 2 = MLP only (features are a cheap function
// of the query index instead of grid lookups). Results of parts 1 and 2 are meaningless by design.
layout(constant_id = 0) const uint NB_EVAL_PART = 0u;

// The 64 queries from nb_group_first on.
void nb_eval_group() {
    uint local = gl_LocalInvocationID.x;
    uint i = nb_group_first + local;
    bool valid = i < pc.count;
    GpuNeuralQuery q = nb_eval_query(i, valid);
    vec3 p0, p1, p2;
    nb_segment_points(pc.box, q.origin, q.dir, q.t_entry, q.t_exit, p0, p1, p2);
#ifdef NB_SPLIT_FEATURES
    // The full split query: the MLP's first layer reads the features straight from the buffer (as
    // passes/neural_query_mlp32.comp); the breakdown parts stage them.
    if (NB_EVAL_PART == 0u) {
        nb_mlp_forward_coopmat_split(); // whole workgroup, uniform control flow (a specialisation constant)
    } else {
#else
    {
#endif
        if (NB_EVAL_PART == 2u) {
            for (uint f = 0u; f < NB_MLP_INPUTS; f += 4u) {
                vec4 v;
                for (uint c = 0u; c < 4u; ++c) v[c] = float(((i * 7u + f + c) & 15u)) * (1.0f / 16.0f) + p0.x;
                nb_coop_x_write4(local, f, v); // packing rounds to fp16
            }
        } else {
#ifdef NB_SPLIT_FEATURES
            nb_coop_stage_split_features(local, valid, i);
#else
            nb_coop_stage_features(local, valid, p0, p1, p2);
#endif
        }
        // Each subgroup stages and runs the MLP on only its own 32 rows: with NB_COOP_FAST a subgroup
        // barrier (shared-memory semantics) lets one subgroup's MLP overlap the other's gather.
        NB_COOP_SYNC();
        if (NB_EVAL_PART != 1u) nb_mlp_forward_coopmat(); // whole workgroup, uniform control flow
    }
    if (!valid) return;
    float y[NB_MLP_OUTPUTS];
    for (uint r = 0u; r < NB_MLP_OUTPUTS; ++r) {
        float pre = NB_EVAL_PART == 1u ? nb_coop_x_read(local, r * 12u) : nb_sh_y[local * NB_COOP_Y_STRIDE + r];
        y[r] = nb_sigmoid(pre);
    }
    hits[i] = nb_neural_decode(pc.box, y, q.t_entry, q.t_exit, length(q.dir), pc.threshold);
}

void main() {
    nb_group_first = pc.first + gl_WorkGroupID.x * NB_NEURAL_GROUP; // queries [pc.first, pc.count)
    nb_eval_group();
}
