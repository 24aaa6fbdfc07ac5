// Level table of the hash grid, tcnn GridEncoding constructor semantics (see level_table.h).
#include "engine/neural/level_table.h"

#include <cmath>
#include <limits>
#include <string>

#include "engine/core/error.h"

namespace nbvh::neural {

float grid_scale(uint32_t level, float per_level_scale, uint32_t base_resolution) {
    // tcnn: exp2f(level * log2_per_level_scale) * base_resolution - 1.0f, with log2 taken in float.
    const float log2_scale = std::log2(per_level_scale);
    return std::exp2(float(level) * log2_scale) * float(base_resolution) - 1.0f;
}

uint32_t grid_resolution(float scale) { return uint32_t(std::ceil(scale)) + 1u; }

std::vector<GpuHashLevel> make_level_table(const NeuralConfig& cfg) {
    if (cfg.grid_levels != NB_GRID_MAX_LEVELS || cfg.grid_features != NB_GRID_FEATURES)
        throw Error("neural config: the renderer supports " + std::to_string(NB_GRID_MAX_LEVELS) + " grid levels x " +
                    std::to_string(NB_GRID_FEATURES) + " features, got " + std::to_string(cfg.grid_levels) + " x " +
                    std::to_string(cfg.grid_features));
    if (cfg.base_resolution < 2u || cfg.base_resolution > 4096u)
        throw Error("neural config: base resolution " + std::to_string(cfg.base_resolution) + " is outside [2, 4096]");
    if (!std::isfinite(cfg.per_level_scale) || cfg.per_level_scale < 1.0f || cfg.per_level_scale > 16.0f)
        throw Error("neural config: per-level scale " + std::to_string(cfg.per_level_scale) + " is outside [1, 16]");
    if (cfg.log2_hash_size < 4u || cfg.log2_hash_size > NB_GRID_MAX_LOG2_HASH)
        throw Error("neural config: log2 hash size " + std::to_string(cfg.log2_hash_size) + " is outside [4, " +
                    std::to_string(NB_GRID_MAX_LOG2_HASH) + "]");

    std::vector<GpuHashLevel> levels(cfg.grid_levels);
    const uint64_t table = uint64_t(1) << cfg.log2_hash_size;
    uint64_t offset = 0;
    for (uint32_t l = 0; l < cfg.grid_levels; ++l) {
        const float scale = grid_scale(l, cfg.per_level_scale, cfg.base_resolution);
        if (!std::isfinite(scale) || scale > 1.0e8f)
            throw Error("neural config: grid level " + std::to_string(l) + " is too fine (scale " +
                        std::to_string(scale) + ")");
        const uint64_t res = grid_resolution(scale);
        // tcnn saturates res^3 at UINT32_MAX/2, rounds it up to a multiple of 8, then caps at 2^T.
        const uint64_t max_params = std::numeric_limits<uint32_t>::max() / 2;
        const bool huge = double(res) * double(res) * double(res) > double(max_params);
        const uint64_t dense = huge ? max_params : res * res * res; // no overflow: res^3 < 2^31 here
        uint64_t params = huge ? max_params : dense;
        params = (params + 7u) / 8u * 8u;
        const uint64_t size = std::min(params, table);
        GpuHashLevel& lv = levels[l];
        lv.offset = uint32_t(offset);
        lv.size = uint32_t(size);
        lv.resolution = uint32_t(res);
        lv.scale = scale;
        // tcnn grid_index hashes iff size < stride, where stride reaches res^3 unless the loop stopped
        // early because stride already exceeded size: equivalent to size < res^3.
        lv.hashed = (huge || size < dense) ? 1u : 0u;
        lv.pad0 = lv.pad1 = lv.pad2 = 0u;
        offset += size;
    }
    if (offset > (uint64_t(1) << 31) / NB_GRID_FEATURES)
        throw Error("neural config: hash grid of " + std::to_string(offset) + " entries is too large");
    return levels;
}

uint64_t level_table_entries(const std::vector<GpuHashLevel>& levels) {
    if (levels.empty()) return 0;
    return uint64_t(levels.back().offset) + levels.back().size;
}

void validate_level_table(const std::vector<GpuHashLevel>& levels) {
    if (levels.size() != NB_GRID_MAX_LEVELS)
        throw Error("level table: " + std::to_string(levels.size()) + " levels, expected " +
                    std::to_string(NB_GRID_MAX_LEVELS));
    uint64_t expect_offset = 0;
    for (size_t l = 0; l < levels.size(); ++l) {
        const GpuHashLevel& lv = levels[l];
        const std::string at = "level table: level " + std::to_string(l) + ": ";
        if (lv.offset != expect_offset) throw Error(at + "offset " + std::to_string(lv.offset) + " is not contiguous");
        if (lv.size == 0u || lv.size > (1u << NB_GRID_MAX_LOG2_HASH)) throw Error(at + "invalid size " + std::to_string(lv.size));
        if (lv.resolution < 2u || lv.resolution >= NB_LEVEL_HASHED_BIT) // the GPU packs the flag in bit 31
            throw Error(at + "invalid resolution " + std::to_string(lv.resolution));
        if (!std::isfinite(lv.scale) || lv.scale <= 0.0f || lv.scale > float(lv.resolution))
            throw Error(at + "invalid scale " + std::to_string(lv.scale));
        if (lv.hashed > 1u || lv.pad0 != 0u || lv.pad1 != 0u || lv.pad2 != 0u) throw Error(at + "invalid flags or padding");
        const double dense = double(lv.resolution) * lv.resolution * lv.resolution;
        const bool should_hash = double(lv.size) < dense;
        if ((lv.hashed != 0u) != should_hash) throw Error(at + "hashed flag disagrees with size and resolution");
        if (!should_hash && double(lv.size) >= dense + 8.0) throw Error(at + "dense level larger than its grid");
        expect_offset += lv.size;
    }
    if (expect_offset > (uint64_t(1) << 31) / NB_GRID_FEATURES) throw Error("level table: grid too large");
}

} // namespace nbvh::neural
