// Neural queries of a flat list through the fused cooperative-matrix MLP, fp32 accumulators;
// (every MLP loop unrolled, subgroup barriers: lib/neural_mlp_coopmat.glsl NB_COOP_FAST).
#version 460
#define NB_COOP_ACC_BITS 32
#define NB_COOP_FAST 1
#include "lib/neural_eval_coopmat_main.glsl"
