// The default hash-table size of `nbvh train` (issue 10, "compact"): the largest 2^T up to the backend's
// maximum (CPU 2^15, CUDA 2^18, the paper's) whose grid is at most a fifth of the mesh + BLAS it
// replaces, so a default model is always at least ~5x smaller than its unique geometry (the paper's
// fixed 2^18 made a 10.4 MiB model of the 6.6 MiB bunny). Floor 2^12. --hash-log2 overrides it.
#pragma once
#include <cstdint>

#include "engine/neural/neural_config.h"
#include "trainer/training_asset.h"

namespace nbvh {

inline constexpr uint32_t COMPACT_HASH_MIN_LOG2 = 12;
inline constexpr uint64_t COMPACT_HASH_RATIO = 5; // grid <= geometry / 5

// Grid bytes (fp16 features) of `cfg` with log2 hash size `log2`.
uint64_t grid_bytes(NeuralConfig cfg, uint32_t log2);

// The rule above for a geometry of `classical_bytes` (engine/neural/model_file.h mesh_and_blas_bytes).
uint32_t compact_hash_log2(const NeuralConfig& cfg, uint64_t classical_bytes, uint32_t max_log2);
uint32_t compact_hash_log2(const TrainingAsset& asset, const NeuralConfig& cfg, uint32_t max_log2);

} // namespace nbvh
