// The MLP half of the split query (flat query list, for the benchmark and tests): the fused cooperative-matrix MLP (fp32
// accumulators, NB_COOP_FAST) on the features passes/neural_eval_gather.comp wrote.
#version 460
#define NB_COOP_ACC_BITS 32
#define NB_COOP_FAST 1
#define NB_SPLIT_FEATURES 1
#include "lib/neural_eval_coopmat_main.glsl"
