// Hyperparameters of one N-BVH model (stored in the .nbvh file). Defaults follow the paper (§4) and the
// official configs (reference notes §2-3).
#pragma once
#include <cstdint>

#include "shaders/shared/neural_config.h"

namespace nbvh {

struct NeuralConfig {
    uint32_t grid_levels = NB_GRID_MAX_LEVELS;
    uint32_t grid_features = NB_GRID_FEATURES;
    uint32_t base_resolution = 8;
    float per_level_scale = 2.0f;
    uint32_t log2_hash_size = 18;   // entries per hashed level = 2^log2_hash_size
    uint32_t segment_points = NB_SEGMENT_POINTS;
    uint32_t mlp_width = NB_MLP_WIDTH;
    uint32_t mlp_hidden_layers = NB_MLP_HIDDEN_LAYERS;
    uint32_t mlp_outputs = NB_MLP_OUTPUTS;
};

} // namespace nbvh
