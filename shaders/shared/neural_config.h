// Sizes of the N-BVH network that shape arrays (GLSL needs compile-time sizes). The model file stores
// the full hyperparameters; a model whose sizes differ from these is rejected by the renderer.
// Paper §4 / official notes §2-3: 8 levels x 4 features, 3 points -> 96 inputs, 64 wide, 4 hidden
// layers (5 matrices, no biases), 8 outputs padded to 16.
#ifndef NB_NEURAL_CONFIG_H
#define NB_NEURAL_CONFIG_H
#include "compat.h"

#define NB_GRID_MAX_LEVELS 8u          // levels of the multi-resolution hash grid
#define NB_GRID_FEATURES 4u            // features per level (fp16)
#define NB_SEGMENT_POINTS 3u           // entry, middle, exit of the ray/leaf segment
#define NB_POINT_FEATURES (NB_GRID_MAX_LEVELS * NB_GRID_FEATURES)           // 32
#define NB_MLP_INPUTS (NB_SEGMENT_POINTS * NB_POINT_FEATURES)               // 96
#define NB_MLP_WIDTH 64u
#define NB_MLP_HIDDEN_LAYERS 4u        // hidden layers; matrices = hidden layers + 1
#define NB_MLP_OUTPUTS 8u              // visibility, depth, normal(3), albedo(3)
#define NB_MLP_OUTPUTS_PADDED 16u      // last matrix is 16 x 64 (tcnn pads the output to 16)

// Output slots (official notes §3 table).
#define NB_OUT_VISIBILITY 0u
#define NB_OUT_DEPTH 1u
#define NB_OUT_NORMAL 2u
#define NB_OUT_ALBEDO 5u

#endif
