// Neural queries of a flat list through the fused cooperative-matrix MLP, fp32 accumulators.
#version 460
#define NB_COOP_ACC_BITS 32
#include "lib/neural_eval_coopmat_main.glsl"
