// Neural query pass, scalar fp16 path (every Vulkan 1.2 device; no subgroup-size assumption).
#version 460
#include "lib/bindings.glsl"
#include "lib/neural_bindings.glsl"
#include "lib/neural_grid.glsl"
#include "lib/neural_mlp_scalar.glsl"
#include "lib/neural_query_pass.glsl"

layout(local_size_x = NB_NEURAL_GROUP) in;

void main() {
    NbPendingQuery r = nb_load_pending(gl_GlobalInvocationID.x);
    if (!r.valid) return;
    vec3 p0, p1, p2;
    nb_segment_points(neural_params.box, r.org, r.dir, r.pl.t_enter, r.pl.t_exit, p0, p1, p2);
    float y[NB_MLP_OUTPUTS];
    nb_neural_forward_scalar(p0, p1, p2, y);
    nb_apply_neural_result(r, y);
}
