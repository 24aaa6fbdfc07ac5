// Fused tensor-core MLP of the N-BVH network (shared/mlp.h) with GL_NV_cooperative_matrix: a workgroup
// of NB_NEURAL_GROUP (64) invocations = 2 subgroups of 32 evaluates 64 queries; each subgroup owns 32
// rows (queries) of the activation matrices. The features are staged in shared memory; with NB_COOP_FAST
// the activations of hidden layers stay in registers as fp16 matrices (each layer's output tiles are the
// next layer's A operands), else they go back to shared memory in place between layers; weights are read as 16x16 fp16 tiles straight from the storage buffer
// (38 KiB, L1/L2 resident), each B tile once per subgroup and layer, from a copy with every matrix
// transposed and tiled (engine/render/neural_model_gpu.h transpose_mlp, shared/mlp.h
// nb_coop_weight_slot) so each B = W^T tile is 512 contiguous bytes (4 cache lines, not 16).
// Per layer: H_out(32 x 64) = relu(H_in(32 x K) * W^T(K x 64)), K = 96 or 64,
// 16x16x16 tiles, accumulators fp32 (NB_COOP_ACC_BITS 32, rounding points of mlp.h R3/R4 with a
// different summation order) or fp16 (16, for devices without fp32 accumulation).
// Shared memory: 64x104 halves (features; in place for every layer without NB_COOP_FAST) + 64x20 floats
// = 18 KiB (48 KiB on NVIDIA).
//
// Only compiled into passes that are created on devices with VK_NV_cooperative_matrix, 16x16x16 fp16
// shapes and subgroup size 32 (engine/render/neural_model_gpu.cpp checks). The including shader
// declares `uvec4 neural_mlp_tiles[];` (the TRANSPOSED, tiled weight buffer in 16-byte words, 8 halves
// each: a tile is 32 words, one tile row 2), defines NB_COOP_ACC_BITS,
// fills nb_sh_x (query row r, features in mlp.h input order: nb_coop_x_write4) and calls
// nb_mlp_forward_coopmat() from uniform control flow; the 8 outputs (fp32, before the sigmoid) are then in
// nb_sh_y[r*NB_COOP_Y_STRIDE + 0..7].
#ifndef NB_NEURAL_MLP_COOPMAT_GLSL
#define NB_NEURAL_MLP_COOPMAT_GLSL
#extension GL_NV_cooperative_matrix : require
#extension GL_KHR_memory_scope_semantics : require
#extension GL_EXT_shader_explicit_arithmetic_types_float16 : require
#extension GL_EXT_control_flow_attributes : require
#extension GL_KHR_shader_subgroup_basic : require
#include "shared/mlp.h"
#include "shared/neural_gpu.h"

#if NB_COOP_ACC_BITS == 32
#define NB_ACC_T float
#else
#define NB_ACC_T float16_t
#endif
#define NB_COOP_ROWS NB_NEURAL_COOP_SUBGROUP // queries per subgroup
// Row stride of the activation buffer in halves: 96 features + 8 padding = 52 words, a multiple of
// 16 bytes (cooperative-matrix loads) that spreads the per-invocation feature stores over 8 banks
// instead of 2.
#define NB_COOP_STRIDE 104u
// The activation buffer is an array of uvec4 (8 halves), so that the driver knows every row and tile
// is 16-byte aligned; cooperative-matrix loads and stores address it in units of uvec4 (offsets and
// strides / 8). The staging writes a level's 4 features as one 64-bit half of a word (16-bit stores at
// this stride conflict 4-way on the banks).
#define NB_COOP_STRIDE_V (NB_COOP_STRIDE / 8u)
// Row stride of the fp32 output buffer: 20 floats instead of 16, so reading a row's 8 outputs
// conflicts 4-way instead of 16-way (80 bytes, still a multiple of 16 for coopMatStoreNV).
#define NB_COOP_Y_STRIDE 20u

// NB_COOP_FAST (defined by the including pass; H200 figures in results/neural/README.md v8-v10):
// NB_COOP_FAST 1: every MLP loop fully unrolled (no dynamically indexed cooperative-matrix arrays or
// elements) and only subgroup barriers inside the MLP (each subgroup reads and writes only its own 32
// rows, so no other subgroup has to wait): MLP alone 0.63 -> 1.77 G queries/s; and the paired-lane
// gather of lib/neural_grid.glsl, NB_GATHER_LEVELS levels at a time (v17). The fp16-accumulator
// kernel (coop16, for devices without fp32 accumulation) keeps the earlier looped form (0) and the
// one-query-per-lane gather. Both read the tiled weights (MLP alone 1.77 -> 3.14 G/s, v17).
// NB_COOP_FAST also keeps the hidden activations in registers (nb_mlp_forward_coopmat below): the
// features' gathers and the MLP's shared-memory tiles share the SM's L1/shared-memory data path, so the
// 32 KiB per subgroup and batch that the in-place layers moved through shared memory slowed the gathers
// of the other subgroups (H200: MLP alone 3.06 -> 4.05 G/s, fused random queries 1.02 -> 1.14 G/s,
// coherent 1.17 -> 1.30; 170 -> 183 registers; results/neural/README.md).
#ifndef NB_COOP_FAST
#define NB_COOP_FAST 0
#endif
#if NB_COOP_FAST
#define NB_UNROLL [[unroll]]
#define NB_COOP_SYNC() subgroupBarrier()
#else
#define NB_UNROLL
#define NB_COOP_SYNC() barrier()
#endif

// Layer inputs and outputs, in place: each layer loads its whole input tile set into accumulators
// before any output is stored (a barrier separates the two), so one buffer serves all layers.
shared uvec4 nb_sh_x[NB_NEURAL_GROUP * NB_COOP_STRIDE_V];
shared float nb_sh_y[NB_NEURAL_GROUP * NB_COOP_Y_STRIDE];

// Features f0..f0+3 (f0 a multiple of 4) of row `row`, already rounded to fp16 (exact when packed).
void nb_coop_x_write4(uint row, uint f0, vec4 v) {
    uvec2 e = uvec2(packHalf2x16(v.xy), packHalf2x16(v.zw));
    uint i = row * NB_COOP_STRIDE_V + f0 / 8u;
    if ((f0 & 4u) == 0u)
        nb_sh_x[i].xy = e;
    else
        nb_sh_x[i].zw = e;
}
float nb_coop_x_read(uint row, uint f) {
    uint w = nb_sh_x[row * NB_COOP_STRIDE_V + f / 8u][(f / 2u) & 3u];
    vec2 h = unpackHalf2x16(w);
    return (f & 1u) != 0u ? h.y : h.x;
}

#define NB_FCM(BITS) fcoopmatNV<BITS, gl_ScopeSubgroup, 16, 16>

// A tile (rows ROW..ROW+15, features KT*16..+15) of the layer input staged in nb_sh_x.
#define NB_COOP_LOAD_A_SHARED(A, ROW, KT) \
    coopMatLoadNV(A, nb_sh_x, (ROW) * NB_COOP_STRIDE_V + (KT) * 2u, NB_COOP_STRIDE_V, false)
#ifdef NB_SPLIT_FEATURES
// ... of the features in the split query's features buffer (shared/neural_gpu.h nb_split_tile_word: the
// workgroup's pairs NB_SPLIT_GROUP_FIRST + row, by default gl_WorkGroupID.x * NB_NEURAL_GROUP; the includer
// declares `uvec4 split_feature_tiles[]`), straight from global memory. Rows of invalid pairs hold stale or unwritten
// features: a row's products depend on that row alone, and its outputs are not used.
#ifndef NB_SPLIT_GROUP_FIRST
#define NB_SPLIT_GROUP_FIRST (gl_WorkGroupID.x * NB_NEURAL_GROUP)
#endif
#define NB_COOP_LOAD_A_SPLIT(A, ROW, KT)                                                              \
    coopMatLoadNV(A, split_feature_tiles, nb_split_tile_word(NB_SPLIT_GROUP_FIRST + (ROW), (KT)),     \
                  NB_SPLIT_TILE_ROW_WORDS, false)
#endif

// ACC[0..7] = X[:, 0:K] * W_m^T for the 32 rows of this subgroup, the A tiles loaded by LOAD_A:
// ACC[nt] = rows row0..+15, output columns nt*16..+15; ACC[4 + nt] = rows row0+16..+31.
#define NB_COOP_ACC_FROM(ACC, K, WOFF, LOAD_A)                                                        \
    NB_UNROLL for (uint j = 0u; j < 8u; ++j) ACC[j] = NB_FCM(NB_COOP_ACC_BITS)(NB_ACC_T(0.0));        \
    NB_UNROLL for (uint kt = 0u; kt < (K) / 16u; ++kt) {                                              \
        NB_FCM(16) a0;                                                                                \
        NB_FCM(16) a1;                                                                                \
        LOAD_A(a0, row0, kt);                                                                         \
        LOAD_A(a1, row0 + 16u, kt);                                                                   \
        NB_UNROLL for (uint nt = 0u; nt < 4u; ++nt) {                                                 \
            NB_FCM(16) b;                                                                             \
            coopMatLoadNV(b, neural_mlp_tiles, ((WOFF) + nb_coop_weight_slot(NB_MLP_WIDTH, kt * 16u, nt * 16u)) / 8u, 2u, false); \
            ACC[nt] = coopMatMulAddNV(a0, b, ACC[nt]);                                                \
            ACC[4u + nt] = coopMatMulAddNV(a1, b, ACC[4u + nt]);                                      \
        }                                                                                             \
    }

// The output layer's fp32 pre-activations (R4) of the subgroup's two row tiles into nb_sh_y.
#define NB_COOP_STORE_OUTPUTS(ACC0, ACC1)                                                             \
    {                                                                                                 \
        NB_FCM(32) y0 = NB_FCM(32)(ACC0);                                                             \
        NB_FCM(32) y1 = NB_FCM(32)(ACC1);                                                             \
        coopMatStoreNV(y0, nb_sh_y, row0 * NB_COOP_Y_STRIDE, NB_COOP_Y_STRIDE, false);                \
        coopMatStoreNV(y1, nb_sh_y, (row0 + 16u) * NB_COOP_Y_STRIDE, NB_COOP_Y_STRIDE, false);        \
    }

// B tile kt of the output layer (16 x 64, rows 8..15 zero padding).
#define NB_COOP_LOAD_OUTPUT_B(B, KT)                                                                  \
    coopMatLoadNV(B, neural_mlp_tiles,                                                                \
                  (nb_mlp_layer_offset(NB_MLP_HIDDEN_LAYERS) + nb_coop_weight_slot(NB_MLP_OUTPUTS_PADDED, (KT) * 16u, 0u)) / 8u, \
                  2u, false)

#if NB_COOP_FAST
// The hidden activations stay in registers as fp16 matrices, H[nt] = rows row0..+15, columns
// nt*16..+15 and H[4 + nt] = rows row0+16..+31: each layer's output tiles are the next layer's A
// operands. The same products and fp32 sums, in the same order, as the in-place form below.

// Layer 0 (K = 96, A tiles from LOAD_A: the staged features or the split query's buffer) into H.
#define NB_COOP_LAYER0_REGS(H, LOAD_A)                                                                \
    {                                                                                                 \
        NB_FCM(NB_COOP_ACC_BITS) acc[8];                                                              \
        NB_COOP_ACC_FROM(acc, NB_MLP_INPUTS, nb_mlp_layer_offset(0u), LOAD_A)                         \
        NB_UNROLL for (uint j = 0u; j < 8u; ++j) {                                                    \
            NB_UNROLL for (int e = 0; e < acc[j].length(); ++e) acc[j][e] = max(acc[j][e], NB_ACC_T(0.0)); \
            H[j] = NB_FCM(16)(acc[j]);                                                                \
        }                                                                                             \
    }

// Hidden layer m >= 1 from and to H, one output column tile at a time (two accumulators).
#define NB_COOP_HIDDEN_REGS(H, M)                                                                     \
    {                                                                                                 \
        NB_FCM(16) o[8];                                                                              \
        NB_UNROLL for (uint nt = 0u; nt < 4u; ++nt) {                                                 \
            NB_FCM(NB_COOP_ACC_BITS) c0 = NB_FCM(NB_COOP_ACC_BITS)(NB_ACC_T(0.0));                    \
            NB_FCM(NB_COOP_ACC_BITS) c1 = c0;                                                         \
            NB_UNROLL for (uint kt = 0u; kt < 4u; ++kt) {                                             \
                NB_FCM(16) b;                                                                         \
                coopMatLoadNV(b, neural_mlp_tiles, (nb_mlp_layer_offset(M) + nb_coop_weight_slot(NB_MLP_WIDTH, kt * 16u, nt * 16u)) / 8u, 2u, false); \
                c0 = coopMatMulAddNV(H[kt], b, c0);                                                   \
                c1 = coopMatMulAddNV(H[4u + kt], b, c1);                                              \
            }                                                                                         \
            NB_UNROLL for (int e = 0; e < c0.length(); ++e) {                                         \
                c0[e] = max(c0[e], NB_ACC_T(0.0));                                                    \
                c1[e] = max(c1[e], NB_ACC_T(0.0));                                                    \
            }                                                                                         \
            o[nt] = NB_FCM(16)(c0);                                                                   \
            o[4u + nt] = NB_FCM(16)(c1);                                                              \
        }                                                                                             \
        NB_UNROLL for (uint j = 0u; j < 8u; ++j) H[j] = o[j];                                         \
    }

// The whole MLP of the subgroup's 32 rows, layer 0's A tiles from LOAD_A (a macro, not a function
// taking the register matrices: no cooperative-matrix arrays passed or indexed at run time).
#define NB_COOP_FORWARD_REGS(LOAD_A)                                                                  \
    uint row0 = (gl_LocalInvocationID.x / NB_COOP_ROWS) * NB_COOP_ROWS;                               \
    NB_FCM(16) h[8];                                                                                  \
    NB_COOP_LAYER0_REGS(h, LOAD_A)                                                                    \
    NB_COOP_HIDDEN_REGS(h, 1u)                                                                        \
    NB_COOP_HIDDEN_REGS(h, 2u)                                                                        \
    NB_COOP_HIDDEN_REGS(h, 3u)                                                                        \
    NB_FCM(NB_COOP_ACC_BITS) acc0 = NB_FCM(NB_COOP_ACC_BITS)(NB_ACC_T(0.0));                          \
    NB_FCM(NB_COOP_ACC_BITS) acc1 = acc0;                                                             \
    NB_UNROLL for (uint kt = 0u; kt < NB_MLP_WIDTH / 16u; ++kt) {                                     \
        NB_FCM(16) b;                                                                                 \
        NB_COOP_LOAD_OUTPUT_B(b, kt);                                                                 \
        acc0 = coopMatMulAddNV(h[kt], b, acc0);                                                       \
        acc1 = coopMatMulAddNV(h[4u + kt], b, acc1);                                                  \
    }                                                                                                 \
    NB_COOP_STORE_OUTPUTS(acc0, acc1)                                                                 \
    NB_COOP_SYNC();

void nb_mlp_forward_coopmat() { NB_COOP_FORWARD_REGS(NB_COOP_LOAD_A_SHARED) }
#ifdef NB_SPLIT_FEATURES
// The split query's MLP: the features read by the tensor cores straight from the features buffer
// (nothing staged in nb_sh_x; the outputs still go to nb_sh_y).
void nb_mlp_forward_coopmat_split() { NB_COOP_FORWARD_REGS(NB_COOP_LOAD_A_SPLIT) }
#endif
#else
// One hidden layer in place in nb_sh_x: X[:, 0:64] = half(relu(X[:, 0:K] * W_m^T)) (all of its input
// tiles are loaded before a barrier, then the outputs stored).
#define NB_COOP_HIDDEN_LAYER(K, WOFF)                                                                 \
    {                                                                                                 \
        NB_FCM(NB_COOP_ACC_BITS) acc[8];                                                              \
        NB_COOP_ACC_FROM(acc, K, WOFF, NB_COOP_LOAD_A_SHARED)                                         \
        NB_COOP_SYNC();                                                                               \
        NB_UNROLL for (uint j = 0u; j < 8u; ++j) {                                                    \
            NB_UNROLL for (int e = 0; e < acc[j].length(); ++e) acc[j][e] = max(acc[j][e], NB_ACC_T(0.0)); \
            NB_FCM(16) o = NB_FCM(16)(acc[j]);                                                        \
            uint r = row0 + (j >> 2u) * 16u;                                                          \
            coopMatStoreNV(o, nb_sh_x, r * NB_COOP_STRIDE_V + (j & 3u) * 2u, NB_COOP_STRIDE_V, false); \
        }                                                                                             \
        NB_COOP_SYNC();                                                                               \
    }

void nb_mlp_forward_coopmat() {
    uint row0 = (gl_LocalInvocationID.x / NB_COOP_ROWS) * NB_COOP_ROWS;
    NB_COOP_HIDDEN_LAYER(NB_MLP_INPUTS, nb_mlp_layer_offset(0u))
    NB_COOP_HIDDEN_LAYER(NB_MLP_WIDTH, nb_mlp_layer_offset(1u))
    NB_COOP_HIDDEN_LAYER(NB_MLP_WIDTH, nb_mlp_layer_offset(2u))
    NB_COOP_HIDDEN_LAYER(NB_MLP_WIDTH, nb_mlp_layer_offset(3u))
    NB_FCM(NB_COOP_ACC_BITS) acc0 = NB_FCM(NB_COOP_ACC_BITS)(NB_ACC_T(0.0));
    NB_FCM(NB_COOP_ACC_BITS) acc1 = acc0;
    NB_UNROLL for (uint kt = 0u; kt < NB_MLP_WIDTH / 16u; ++kt) {
        NB_FCM(16) b;
        NB_COOP_LOAD_OUTPUT_B(b, kt);
        NB_FCM(16) a0;
        NB_FCM(16) a1;
        coopMatLoadNV(a0, nb_sh_x, row0 * NB_COOP_STRIDE_V + kt * 2u, NB_COOP_STRIDE_V, false);
        coopMatLoadNV(a1, nb_sh_x, (row0 + 16u) * NB_COOP_STRIDE_V + kt * 2u, NB_COOP_STRIDE_V, false);
        acc0 = coopMatMulAddNV(a0, b, acc0);
        acc1 = coopMatMulAddNV(a1, b, acc1);
    }
    NB_COOP_STORE_OUTPUTS(acc0, acc1)
    NB_COOP_SYNC();
}
#endif

// Writes one query's 96 features (rounded to fp16, R1) into its row of nb_sh_x, level by level (no
// per-point array stays live); zeros when !valid.
void nb_coop_stage_features(uint local, bool valid, vec3 p0, vec3 p1, vec3 p2) {
#if NB_COOP_FAST
    NB_PAIRED_GATHER_SEGMENT(p0, p1, p2, nb_coop_x_write4(local, nb_feature_slot(k, l, 0u), valid ? f : vec4(0.0f));)
#else
    for (uint k = 0u; k < NB_SEGMENT_POINTS; ++k) {
        vec3 p = k == 0u ? p0 : (k == 1u ? p1 : p2);
        for (uint l = 0u; l < NB_GRID_MAX_LEVELS; ++l)
            nb_coop_x_write4(local, nb_feature_slot(k, l, 0u), valid ? nb_neural_level_features(p, l) : vec4(0.0f));
    }
#endif
}

// The split query's MLP pass (shared/neural_gpu.h NB_SPLIT_*): query row `local`'s 96 features from
// the features buffer the gather pass wrote (quad s of pair `index` at nb_split_index; the
// includer defines NB_SPLIT_FEATURES and declares `uvec2 split_features[]`); zeros when !valid.
#ifdef NB_SPLIT_FEATURES
void nb_coop_stage_split_features(uint local, bool valid, uint index) {
    for (uint s = 0u; s < NB_SPLIT_FEATURE_QUADS; ++s) {
        uvec2 e = valid ? split_features[nb_split_index(index, s)] : uvec2(0u);
        uint w = local * NB_COOP_STRIDE_V + s / 2u; // quad s holds features 4s..4s+3 (nb_coop_x_write4)
        if ((s & 1u) == 0u)
            nb_sh_x[w].xy = e;
        else
            nb_sh_x[w].zw = e;
    }
}
#endif

#endif
