// Neural query pass, fused cooperative-matrix MLP with fp32 accumulators.
#version 460
#define NB_COOP_ACC_BITS 32
#include "lib/neural_query_coopmat_main.glsl"
