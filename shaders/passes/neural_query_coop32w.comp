// Neural query pass through the fused cooperative-matrix MLP, fp32 accumulators;
// variant: unrolled loops, subgroup barriers, hidden-layer weights in shared memory (lib/neural_mlp_coopmat.glsl).
#version 460
#define NB_COOP_ACC_BITS 32
#define NB_COOP_FAST 1
#define NB_COOP_GATHER_UNROLL 1
#define NB_COOP_WSHARED 1
#include "lib/neural_query_coopmat_main.glsl"
