// Fused tensor-core MLP of the N-BVH network (shared/mlp.h) with GL_NV_cooperative_matrix: a workgroup
// of NB_NEURAL_GROUP (64) invocations = 2 subgroups of 32 evaluates 64 queries; each subgroup owns 32
// rows (queries) of the activation matrices. Features and activations stay in shared memory
// (on chip) between layers; weights are read as 16x16 fp16 tiles straight from the storage buffer
// (38 KiB, L1/L2 resident). Per layer: H_out(32 x 64) = relu(H_in(32 x K) * W^T(K x 64)), K = 96 or 64,
// 16x16x16 tiles, accumulators fp32 (NB_COOP_ACC_BITS 32, rounding points of mlp.h R3/R4 with a
// different summation order) or fp16 (16, for devices without fp32 accumulation).
// Shared memory: 64x96 + 64x64 halves + 64x16 floats = 24 KiB (limit 48 KiB on NVIDIA).
//
// Only compiled into passes that are created on devices with VK_NV_cooperative_matrix, 16x16x16 fp16
// shapes and subgroup size 32 (engine/render/neural_model_gpu.cpp checks). The including shader
// declares `float16_t neural_mlp_h[];` (the weight buffer seen as halves), defines NB_COOP_ACC_BITS,
// fills nb_sh_x (query row r at r*96, features in mlp.h input order) and calls
// nb_mlp_forward_coopmat() from uniform control flow; outputs (after the sigmoid) are then in
// nb_sh_y[r*16 + 0..7].
#ifndef NB_NEURAL_MLP_COOPMAT_GLSL
#define NB_NEURAL_MLP_COOPMAT_GLSL
#extension GL_NV_cooperative_matrix : require
#extension GL_KHR_memory_scope_semantics : require
#extension GL_EXT_shader_explicit_arithmetic_types_float16 : require
#include "shared/mlp.h"
#include "shared/neural_gpu.h"

#if NB_COOP_ACC_BITS == 32
#define NB_ACC_T float
#else
#define NB_ACC_T float16_t
#endif
#define NB_COOP_ROWS NB_NEURAL_COOP_SUBGROUP // queries per subgroup

shared float16_t nb_sh_x[NB_NEURAL_GROUP * NB_MLP_INPUTS]; // layer inputs (stride 96 or 64)
shared float16_t nb_sh_h[NB_NEURAL_GROUP * NB_MLP_WIDTH];  // hidden activations (stride 64)
shared float nb_sh_y[NB_NEURAL_GROUP * NB_MLP_OUTPUTS_PADDED];

// One hidden layer for the 32 rows of subgroup `sg`: OUT = half(relu(IN * W_m^T)).
#define NB_COOP_HIDDEN_LAYER(M, IN, K, OUT)                                                           \
    for (uint nt = 0u; nt < NB_MLP_WIDTH / 16u; ++nt) {                                               \
        fcoopmatNV<NB_COOP_ACC_BITS, gl_ScopeSubgroup, 16, 16> acc0 =                                 \
            fcoopmatNV<NB_COOP_ACC_BITS, gl_ScopeSubgroup, 16, 16>(NB_ACC_T(0.0));                    \
        fcoopmatNV<NB_COOP_ACC_BITS, gl_ScopeSubgroup, 16, 16> acc1 = acc0;                           \
        for (uint kt = 0u; kt < (K) / 16u; ++kt) {                                                    \
            fcoopmatNV<16, gl_ScopeSubgroup, 16, 16> b;                                               \
            coopMatLoadNV(b, neural_mlp_h, nb_mlp_layer_offset(M) + nt * 16u * (K) + kt * 16u, (K), true); \
            fcoopmatNV<16, gl_ScopeSubgroup, 16, 16> a0;                                              \
            fcoopmatNV<16, gl_ScopeSubgroup, 16, 16> a1;                                              \
            coopMatLoadNV(a0, IN, row0 * (K) + kt * 16u, (K), false);                                 \
            coopMatLoadNV(a1, IN, (row0 + 16u) * (K) + kt * 16u, (K), false);                         \
            acc0 = coopMatMulAddNV(a0, b, acc0);                                                      \
            acc1 = coopMatMulAddNV(a1, b, acc1);                                                      \
        }                                                                                             \
        for (int e = 0; e < acc0.length(); ++e) {                                                     \
            acc0[e] = max(acc0[e], NB_ACC_T(0.0));                                                    \
            acc1[e] = max(acc1[e], NB_ACC_T(0.0));                                                    \
        }                                                                                             \
        fcoopmatNV<16, gl_ScopeSubgroup, 16, 16> o0 = fcoopmatNV<16, gl_ScopeSubgroup, 16, 16>(acc0); \
        fcoopmatNV<16, gl_ScopeSubgroup, 16, 16> o1 = fcoopmatNV<16, gl_ScopeSubgroup, 16, 16>(acc1); \
        coopMatStoreNV(o0, OUT, row0 * NB_MLP_WIDTH + nt * 16u, NB_MLP_WIDTH, false);                 \
        coopMatStoreNV(o1, OUT, (row0 + 16u) * NB_MLP_WIDTH + nt * 16u, NB_MLP_WIDTH, false);         \
    }                                                                                                 \
    barrier();

void nb_mlp_forward_coopmat() {
    uint row0 = (gl_LocalInvocationID.x / NB_COOP_ROWS) * NB_COOP_ROWS;
    NB_COOP_HIDDEN_LAYER(0u, nb_sh_x, NB_MLP_INPUTS, nb_sh_h)
    NB_COOP_HIDDEN_LAYER(1u, nb_sh_h, NB_MLP_WIDTH, nb_sh_x)
    NB_COOP_HIDDEN_LAYER(2u, nb_sh_x, NB_MLP_WIDTH, nb_sh_h)
    NB_COOP_HIDDEN_LAYER(3u, nb_sh_h, NB_MLP_WIDTH, nb_sh_x)
    // Output layer (16 x 64, rows 8..15 zero padding): fp32 pre-activation (R4).
    {
        fcoopmatNV<NB_COOP_ACC_BITS, gl_ScopeSubgroup, 16, 16> acc0 =
            fcoopmatNV<NB_COOP_ACC_BITS, gl_ScopeSubgroup, 16, 16>(NB_ACC_T(0.0));
        fcoopmatNV<NB_COOP_ACC_BITS, gl_ScopeSubgroup, 16, 16> acc1 = acc0;
        for (uint kt = 0u; kt < NB_MLP_WIDTH / 16u; ++kt) {
            fcoopmatNV<16, gl_ScopeSubgroup, 16, 16> b;
            coopMatLoadNV(b, neural_mlp_h, nb_mlp_layer_offset(NB_MLP_HIDDEN_LAYERS) + kt * 16u, NB_MLP_WIDTH, true);
            fcoopmatNV<16, gl_ScopeSubgroup, 16, 16> a0;
            fcoopmatNV<16, gl_ScopeSubgroup, 16, 16> a1;
            coopMatLoadNV(a0, nb_sh_x, row0 * NB_MLP_WIDTH + kt * 16u, NB_MLP_WIDTH, false);
            coopMatLoadNV(a1, nb_sh_x, (row0 + 16u) * NB_MLP_WIDTH + kt * 16u, NB_MLP_WIDTH, false);
            acc0 = coopMatMulAddNV(a0, b, acc0);
            acc1 = coopMatMulAddNV(a1, b, acc1);
        }
        fcoopmatNV<32, gl_ScopeSubgroup, 16, 16> y0 = fcoopmatNV<32, gl_ScopeSubgroup, 16, 16>(acc0);
        fcoopmatNV<32, gl_ScopeSubgroup, 16, 16> y1 = fcoopmatNV<32, gl_ScopeSubgroup, 16, 16>(acc1);
        coopMatStoreNV(y0, nb_sh_y, row0 * NB_MLP_OUTPUTS_PADDED, NB_MLP_OUTPUTS_PADDED, false);
        coopMatStoreNV(y1, nb_sh_y, (row0 + 16u) * NB_MLP_OUTPUTS_PADDED, NB_MLP_OUTPUTS_PADDED, false);
    }
    barrier();
}

// Writes one query's 96 features (rounded to fp16, R1) into its row of nb_sh_x; zeros when !valid.
void nb_coop_stage_features(uint local, bool valid, vec3 p0, vec3 p1, vec3 p2) {
    float f[NB_POINT_FEATURES];
    for (uint k = 0u; k < NB_SEGMENT_POINTS; ++k) {
        if (valid) {
            nb_neural_point_features(k == 0u ? p0 : (k == 1u ? p1 : p2), f);
        } else {
            for (uint i = 0u; i < NB_POINT_FEATURES; ++i) f[i] = 0.0f;
        }
        for (uint i = 0u; i < NB_POINT_FEATURES; ++i)
            nb_sh_x[local * NB_MLP_INPUTS + k * NB_POINT_FEATURES + i] = float16_t(f[i]);
    }
}

#endif
