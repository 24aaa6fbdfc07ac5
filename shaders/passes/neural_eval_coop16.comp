// Neural queries of a flat list through the fused cooperative-matrix MLP, fp16 accumulators
// (devices whose VK_NV_cooperative_matrix has no fp32-accumulating 16x16x16 shape).
#version 460
#define NB_COOP_ACC_BITS 16
#include "lib/neural_eval_coopmat_main.glsl"
