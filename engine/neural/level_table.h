// The per-level table of the hash grid (offset, size, resolution, scale), computed once when a model
// is created, exactly as tiny-cuda-nn's GridEncoding constructor does (notes tiny-cuda-nn §B.2-B.3),
// and then stored in the model file. Readers never recompute it; they validate it
// (validate_level_table) against the stored hyperparameters.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/neural/neural_config.h"
#include "shaders/shared/hashgrid.h"

namespace nbvh::neural {

// tcnn grid_scale: exp2f(level * log2f(per_level_scale)) * base_resolution - 1 (float arithmetic).
float grid_scale(uint32_t level, float per_level_scale, uint32_t base_resolution);
// tcnn grid_resolution: ceil(scale) + 1.
uint32_t grid_resolution(float scale);

// Levels 0..cfg.grid_levels-1 with prefix-sum offsets. Throws nbvh::Error on hyperparameters outside
// what the renderer supports (levels/features other than the compiled sizes, base resolution 0,
// per-level scale < 1 or not finite, log2 hash size outside [4, NB_GRID_MAX_LOG2_HASH]).
std::vector<GpuHashLevel> make_level_table(const NeuralConfig& cfg);

// Total entries (offset of the end of the last level). Values = entries * NB_GRID_FEATURES.
uint64_t level_table_entries(const std::vector<GpuHashLevel>& levels);

// Checks a table read from a file: contiguous offsets, sizes > 0, hashed flag consistent with
// size < res^3, scale finite and positive, padding zero. Throws nbvh::Error naming the first problem.
void validate_level_table(const std::vector<GpuHashLevel>& levels);

} // namespace nbvh::neural
