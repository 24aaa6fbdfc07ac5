// The split query's MLP pass: the fused cooperative-matrix MLP (fp32 accumulators, NB_COOP_FAST) on
// the features passes/neural_gather.comp wrote for the round's first split_chunk pairs, then the decode and
// the pair's result as in the fused pass (lib/neural_query_coopmat_main.glsl).
#version 460
#define NB_COOP_ACC_BITS 32
#define NB_COOP_FAST 1
#define NB_SPLIT_FEATURES 1
#include "lib/neural_query_coopmat_main.glsl"
