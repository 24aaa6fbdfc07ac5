#include "engine/render/neural_grid_pack.h"

#include "engine/core/error.h"
#include "engine/render/neural_model_gpu.h"

namespace nbvh::render {

uint32_t ypair_level_count(const std::vector<GpuHashLevel>& levels) {
    uint32_t n = 0;
    uint64_t next = 0;
    while (n < levels.size() && nb_level_ypair_ok(levels[n]) && levels[n].offset == next) {
        next += levels[n].size;
        ++n;
    }
    return n;
}

namespace {
uint32_t ypair_entries_of(const std::vector<GpuHashLevel>& levels, uint32_t count) {
    return count == 0 ? 0u : levels[count - 1].offset + levels[count - 1].size;
}
uint64_t entry_words(const NeuralModel& model) { return (uint64_t(model.grid.size()) + 1) / 2; }
} // namespace

PackedGrid pack_grid(const NeuralModel& model) {
    PackedGrid g;
    g.words = pack_halves(model.grid);
    g.ypair_levels = ypair_level_count(model.levels);
    g.ypair_entries = ypair_entries_of(model.levels, g.ypair_levels);
    if (uint64_t(g.ypair_entries) * NB_GRID_FEATURES > model.grid.size())
        throw Error("the model's hash grid is smaller than its level table says");
    g.words.resize((g.words.size() + 3) / 4 * 4, 0u); // the table starts on a 16-byte word
    g.ypair_base = uint32_t(g.words.size() / 4);
    std::vector<uint32_t> table;
    table.reserve(size_t(g.ypair_entries) * 4);
    for (uint32_t l = 0; l < g.ypair_levels; ++l) {
        const GpuHashLevel& lv = model.levels[l];
        for (uint32_t i = 0; i < lv.size; ++i) {
            const size_t a = lv.offset + i, b = lv.offset + nb_grid_ypair_partner(lv, i);
            table.insert(table.end(), {g.words[2 * a], g.words[2 * a + 1], g.words[2 * b], g.words[2 * b + 1]});
        }
    }
    g.words.insert(g.words.end(), table.begin(), table.end());
    return g;
}

uvec4 ypair_word(const PackedGrid& grid) { return uvec4(grid.ypair_base, grid.ypair_levels, 0u, 0u); }

uint64_t packed_grid_bytes(const NeuralModel& model) {
    const uint64_t ypair = ypair_entries_of(model.levels, ypair_level_count(model.levels));
    return ((entry_words(model) + 3) / 4 + ypair) * 16u;
}

} // namespace nbvh::render
