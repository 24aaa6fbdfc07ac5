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
uint64_t ypair_entries_of(const std::vector<GpuHashLevel>& levels, uint32_t count) {
    return count == 0 ? 0u : uint64_t(levels[count - 1].offset) + levels[count - 1].size;
}
} // namespace

GridLayout grid_layout(const NeuralModel& model, uint64_t max_bytes) {
    GridLayout g;
    g.entry_bytes = (uint64_t(model.grid.size()) * 2 + 15) / 16 * 16; // fp16 halves, padded to 16 bytes
    uint32_t levels = ypair_level_count(model.levels);
    uint64_t entries = ypair_entries_of(model.levels, levels);
    // The table covers entries the grid holds (the level table of a loaded file is validated against it;
    // an inconsistent in-memory model is refused, never read past its end).
    if (entries * NB_GRID_FEATURES > model.grid.size())
        throw Error("the model's hash grid is smaller than its level table says");
    while (levels > 0 && g.entry_bytes + entries * 16 > max_bytes) entries = ypair_entries_of(model.levels, --levels);
    g.ypair_levels = levels;
    g.ypair_entries = uint32_t(entries); // <= the grid's entries: a level holds at most 2^24, 8 levels
    g.ypair_bytes = entries * 16;
    return g;
}

PackedGrid pack_grid(const NeuralModel& model, uint64_t max_bytes) {
    const GridLayout layout = grid_layout(model, max_bytes);
    PackedGrid g;
    g.ypair_levels = layout.ypair_levels;
    g.ypair_entries = layout.ypair_entries;
    g.words = pack_halves(model.grid);
    g.words.reserve((layout.entry_bytes + layout.ypair_bytes) / 4);
    g.words.resize(layout.entry_bytes / 4, 0u); // the table starts on a 16-byte word
    g.ypair_base = uint32_t(g.words.size() / 4);
    for (uint32_t l = 0; l < g.ypair_levels; ++l) {
        const GpuHashLevel& lv = model.levels[l];
        for (uint32_t i = 0; i < lv.size; ++i) {
            const size_t a = size_t(lv.offset) + i, b = size_t(lv.offset) + nb_grid_ypair_partner(lv, i);
            const uint32_t w[4] = {g.words[2 * a], g.words[2 * a + 1], g.words[2 * b], g.words[2 * b + 1]};
            g.words.insert(g.words.end(), w, w + 4); // within the reserved size: no reallocation
        }
    }
    return g;
}

uvec4 ypair_word(const PackedGrid& grid) { return uvec4(grid.ypair_base, grid.ypair_levels, 0u, 0u); }

} // namespace nbvh::render
