// Body of passes/neural_query_coop{16,32}.comp: the neural query pass through the fused
// cooperative-matrix MLP (64 pairs per workgroup; the includer defines NB_COOP_ACC_BITS), and of
// passes/neural_query_mlp32.comp (NB_SPLIT_FEATURES: the split query's MLP pass, its first layer reading
// the features straight from the buffer passes/neural_gather.comp wrote for the round's first
// split_chunk pairs).
#include "lib/bindings.glsl"
#define NB_NEURAL_MLP_AS_TILES 1
#include "lib/neural_bindings.glsl"
#include "lib/neural_grid.glsl"
#include "lib/neural_mlp_coopmat.glsl"
#include "lib/neural_query_pass.glsl"

layout(local_size_x = NB_NEURAL_GROUP) in;

void main() {
#ifdef NB_SPLIT_FEATURES
    // The features stay in the buffer: the MLP's first layer loads them (nb_mlp_forward_coopmat_split).
    NbPendingQuery r = nb_load_pending(gl_GlobalInvocationID.x);
#else
    NbPendingQuery r = nb_load_pending(nb_query_first_pair() + gl_GlobalInvocationID.x);
    vec3 p0, p1, p2;
    nb_segment_points(neural_params.box, r.org, r.dir, r.pl.t_enter, r.pl.t_exit, p0, p1, p2);
    nb_coop_stage_features(gl_LocalInvocationID.x, r.valid, p0, p1, p2);
#endif
#ifdef NB_SPLIT_FEATURES
    nb_mlp_forward_coopmat_split(); // whole workgroup, uniform control flow
#else
    // Each subgroup stages and runs the MLP on only its own 32 rows: with NB_COOP_FAST a subgroup
    // barrier (shared-memory semantics) lets one subgroup's MLP overlap the other's gather.
    NB_COOP_SYNC();
    nb_mlp_forward_coopmat(); // whole workgroup, uniform control flow
#endif
    if (!r.valid) return;
    float y[NB_MLP_OUTPUTS];
    for (uint k = 0u; k < NB_MLP_OUTPUTS; ++k)
        y[k] = nb_sigmoid(nb_sh_y[gl_LocalInvocationID.x * NB_COOP_Y_STRIDE + k]);
    nb_apply_neural_result(r, y);
}
