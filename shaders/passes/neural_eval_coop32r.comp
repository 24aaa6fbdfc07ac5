// Neural queries of a flat list through the fused cooperative-matrix MLP, fp32 accumulators;
// variant: row-tile-wise unrolled MLP, subgroup barriers, gather loops not unrolled (lib/neural_mlp_coopmat.glsl).
#version 460
#define NB_COOP_ACC_BITS 32
#define NB_COOP_FAST 1
#define NB_COOP_GATHER_UNROLL 0
#define NB_COOP_ROWWISE 1
#include "lib/neural_eval_coopmat_main.glsl"
