// The N-BVH MLP (paper §4, official notes §3): 96 -> 64 -> 64 -> 64 -> 64 -> 8 (padded to 16),
// ReLU on hidden layers, sigmoid on every output, NO biases (tcnn MLPs have none).
//
// Weight layout = tcnn FullyFusedMLP parameter order (tiny-cuda-nn notes §A.7, official notes §10),
// so an official network JSON imports by a plain copy of its first 19,456 halves:
//   matrix m = 0..4, each row-major (out x in), matrices contiguous in order:
//     m=0: 64 x 96   at      0   (input layer)
//     m=1: 64 x 64   at   6144
//     m=2: 64 x 64   at  10240
//     m=3: 64 x 64   at  14336
//     m=4: 16 x 64   at  18432   (output layer; rows 8..15 are padding, never read, kept 0)
//   total 19456 weights.  weight(m, row, col) = mlp[nb_mlp_weight_index(m, row, col)].
// Forward: h0 = features (96), h_{m+1} = relu(W_m h_m) for m = 0..3, y = sigmoid(W_4 h_4)[0..7].
//
// fp16 ROUNDING POINTS of the scalar GLSL path (the CPU reference's Precision::fp16_emulated
// reproduces exactly these; the shader must match them):
//   R1 grid values are fp16 (as stored); corner weights are fp32; the trilinear sum of one level is
//      accumulated in fp32 in corner order 0..7 (sum += w * value) and rounded to fp16 once
//      (tcnn accumulates in fp16 instead: an extra <= 8 half-ulp difference, within test bounds);
//   R2 MLP weights are fp16 (as stored);
//   R3 each layer's dot product is accumulated in fp32 over the inputs in column order, then ReLU,
//      then the activation is rounded to fp16 (it is the next layer's fp16 input);
//   R4 the output layer's pre-activation stays fp32; sigmoid in fp32; outputs are fp32.
// Summation order differences (e.g. a tensor-core path) change results by fp32 rounding only, which
// may flip an fp16 rounding of an activation: compare such paths within a bound, never bit-exactly.
#ifndef NB_MLP_H
#define NB_MLP_H
#include "compat.h"
#include "neural_config.h"

#define NB_MLP_MATRICES (NB_MLP_HIDDEN_LAYERS + 1u) // 5
#define NB_MLP_WEIGHT_COUNT                                                                       \
    (NB_MLP_WIDTH * NB_MLP_INPUTS + (NB_MLP_HIDDEN_LAYERS - 1u) * NB_MLP_WIDTH * NB_MLP_WIDTH +   \
     NB_MLP_OUTPUTS_PADDED * NB_MLP_WIDTH) // 19456

// Inputs (columns) of matrix m.
NB_FN uint nb_mlp_layer_inputs(uint m) { return m == 0u ? NB_MLP_INPUTS : NB_MLP_WIDTH; }

// Outputs (rows) of matrix m, padded for the last one (16).
NB_FN uint nb_mlp_layer_outputs(uint m) {
    return m == NB_MLP_HIDDEN_LAYERS ? NB_MLP_OUTPUTS_PADDED : NB_MLP_WIDTH;
}

// First weight of matrix m in the flat weight array.
NB_FN uint nb_mlp_layer_offset(uint m) {
    return m == 0u ? 0u : NB_MLP_WIDTH * NB_MLP_INPUTS + (m - 1u) * NB_MLP_WIDTH * NB_MLP_WIDTH;
}

// Flat index of W_m[row][col] (row = output neuron, col = input).
NB_FN uint nb_mlp_weight_index(uint m, uint row, uint col) {
    return nb_mlp_layer_offset(m) + row * nb_mlp_layer_inputs(m) + col;
}

// Layout of the cooperative-matrix kernels' weight copy (engine/render/neural_model_gpu.h transpose_mlp):
// each matrix transposed (inputs x outputs) and stored as 16x16 tiles, tile (c/16, r/16) row-major
// among the outputs/16 tiles of a tile row, each tile row-major with stride 16. Slot of (input c,
// output r) relative to the matrix offset; `outs` = the matrix's outputs (64 or 16).
NB_FN uint nb_coop_weight_slot(uint outs, uint c, uint r) {
    return ((c / 16u) * (outs / 16u) + r / 16u) * 256u + (c % 16u) * 16u + (r % 16u);
}

NB_FN float nb_relu(float x) { return max(x, 0.0f); }

// Logistic sigmoid, overflow-safe for any finite x (exp of a non-positive argument only).
NB_FN float nb_sigmoid(float x) {
    if (x >= 0.0f) {
        return 1.0f / (1.0f + exp(-x));
    }
    float e = exp(x);
    return e / (1.0f + e);
}

#endif // NB_MLP_H
