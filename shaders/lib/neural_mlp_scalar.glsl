// Scalar MLP of the N-BVH network (shared/mlp.h), one query per invocation, for every Vulkan 1.2
// device (lavapipe included): fp16 weights packed two per uint and unpacked with unpackHalf2x16 (no
// shaderFloat16, no 16-bit storage needed), no subgroup operations. Rounding points R2-R4 of mlp.h:
// fp32 dot products in column order, ReLU, activation rounded to fp16; fp32 output pre-activation,
// fp32 sigmoid. Matches engine/neural/reference_network (Precision::fp16_emulated) up to fp32
// contraction differences.
//
// The including shader declares `uint neural_mlp[];` (NB_MLP_WEIGHT_COUNT / 2 words) and includes
// lib/neural_grid.glsl first.
#ifndef NB_NEURAL_MLP_SCALAR_GLSL
#define NB_NEURAL_MLP_SCALAR_GLSL
#include "shared/mlp.h"

// One hidden layer: out[r] = half(relu(sum_c W_m[r][c] in[c])), `cols` inputs (even).
#define NB_MLP_SCALAR_LAYER(M, IN, COLS, OUT)                                                         \
    for (uint r = 0u; r < NB_MLP_WIDTH; ++r) {                                                        \
        uint base = nb_mlp_weight_index((M), r, 0u) >> 1u;                                            \
        float acc = 0.0f;                                                                             \
        for (uint c = 0u; c < (COLS); c += 2u) {                                                      \
            vec2 w = unpackHalf2x16(neural_mlp[base + (c >> 1u)]);                                    \
            acc += w.x * IN[c];                                                                       \
            acc += w.y * IN[c + 1u];                                                                  \
        }                                                                                             \
        OUT[r] = nb_round_half(nb_relu(acc));                                                         \
    }

void nb_mlp_forward_scalar(float x[NB_MLP_INPUTS], out float y[NB_MLP_OUTPUTS]) {
    float h0[NB_MLP_WIDTH];
    float h1[NB_MLP_WIDTH];
    NB_MLP_SCALAR_LAYER(0u, x, NB_MLP_INPUTS, h0)
    NB_MLP_SCALAR_LAYER(1u, h0, NB_MLP_WIDTH, h1)
    NB_MLP_SCALAR_LAYER(2u, h1, NB_MLP_WIDTH, h0)
    NB_MLP_SCALAR_LAYER(3u, h0, NB_MLP_WIDTH, h1)
    for (uint r = 0u; r < NB_MLP_OUTPUTS; ++r) {
        uint base = nb_mlp_weight_index(NB_MLP_HIDDEN_LAYERS, r, 0u) >> 1u;
        float acc = 0.0f;
        for (uint c = 0u; c < NB_MLP_WIDTH; c += 2u) {
            vec2 w = unpackHalf2x16(neural_mlp[base + (c >> 1u)]);
            acc += w.x * h1[c];
            acc += w.y * h1[c + 1u];
        }
        y[r] = nb_sigmoid(acc); // R4
    }
}

// Features of the 3 points of a segment (query order) and the forward pass. (Point by point through a
// 32-float array with constant-index copies: writing x[] at computed slots level by level measured 2x
// slower on the H200, the array then lives in local memory.)
void nb_neural_forward_scalar(vec3 p0, vec3 p1, vec3 p2, out float y[NB_MLP_OUTPUTS]) {
    float x[NB_MLP_INPUTS];
    float f[NB_POINT_FEATURES];
    nb_neural_point_features(p0, f);
    for (uint i = 0u; i < NB_POINT_FEATURES; ++i) x[i] = f[i];
    nb_neural_point_features(p1, f);
    for (uint i = 0u; i < NB_POINT_FEATURES; ++i) x[NB_POINT_FEATURES + i] = f[i];
    nb_neural_point_features(p2, f);
    for (uint i = 0u; i < NB_POINT_FEATURES; ++i) x[2u * NB_POINT_FEATURES + i] = f[i];
    nb_mlp_forward_scalar(x, y);
}

#endif
