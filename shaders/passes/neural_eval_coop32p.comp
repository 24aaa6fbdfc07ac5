// Neural queries of a flat list through the fused cooperative-matrix MLP, fp32 accumulators;
// variant: g with rolled staging loops, two levels per iteration, corner loop unrolled (16 loads in flight) (lib/neural_mlp_coopmat.glsl).
#version 460
#define NB_COOP_ACC_BITS 32
#define NB_COOP_FAST 1
#define NB_COOP_GATHER_UNROLL 0
#define NB_COOP_GATHER_ROLLED 1
#define NB_COOP_CORNER_UNROLL 1
#define NB_COOP_GATHER_PAIRS 1
#include "lib/neural_eval_coopmat_main.glsl"
