#include "trainer/compact_hash.h"

#include <algorithm>

#include "engine/neural/level_table.h"
#include "engine/neural/model_file.h"

namespace nbvh {

uint64_t grid_bytes(NeuralConfig cfg, uint32_t log2) {
    cfg.log2_hash_size = log2;
    return neural::level_table_entries(neural::make_level_table(cfg)) * cfg.grid_features * 2u;
}

uint32_t compact_hash_log2(const NeuralConfig& cfg, uint64_t classical_bytes, uint32_t max_log2) {
    const uint32_t lo = std::min(COMPACT_HASH_MIN_LOG2, max_log2);
    for (uint32_t t = max_log2; t > lo; --t)
        if (grid_bytes(cfg, t) * COMPACT_HASH_RATIO <= classical_bytes) return t;
    return lo;
}

uint32_t compact_hash_log2(const TrainingAsset& asset, const NeuralConfig& cfg, uint32_t max_log2) {
    const uint64_t vertices = asset.mesh ? asset.mesh->positions.size() : 0;
    return compact_hash_log2(cfg, mesh_and_blas_bytes(asset.triangle_count(), vertices), max_log2);
}

} // namespace nbvh
