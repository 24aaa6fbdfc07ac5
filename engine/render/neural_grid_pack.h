// The hash grid as the GPU reads it: the model's fp16 entries packed two halves per word
// (pack_halves), followed by a y-pair table of its leading dense levels (shared/hashgrid.h, "Y-pair
// table"): entry i of such a level next to the entry of its +y neighbour, 16 bytes, so that the split
// query's gather reads the two corners c and c|2 of a cell in one load (lib/neural_grid.glsl). The
// level buffer gets one more 16-byte word after the levels: (y-pair base in 16-byte words, y-paired
// levels, 0, 0). The table is a copy for speed, counted apart in the memory figures (gpu_memory.h
// grid_ypair); levels are left out of it, finest first, where the whole buffer would pass the device's
// largest storage-buffer binding (128 MiB on lavapipe).
#pragma once
#include <cstdint>
#include <limits>
#include <vector>

#include "engine/neural/model_file.h"
#include "shaders/shared/hashgrid.h"

namespace nbvh::render {

struct PackedGrid {
    std::vector<uint32_t> words; // the entries (2 words each), padding to 16 bytes, the y-pair table
    uint32_t ypair_base = 0;     // first 16-byte word of the y-pair table
    uint32_t ypair_levels = 0;   // levels 0..ypair_levels-1 have y-pair entries
    uint32_t ypair_entries = 0;  // 16-byte words of the table (the entries of those levels)
};

// Leading levels that qualify (nb_level_ypair_ok) and whose entries start at 0 and follow each other.
uint32_t ypair_level_count(const std::vector<GpuHashLevel>& levels);

// How the grid buffer is laid out for a binding of at most `max_bytes`.
struct GridLayout {
    uint64_t entry_bytes = 0;  // the entries and the padding to 16 bytes
    uint64_t ypair_bytes = 0;  // the y-pair table
    uint32_t ypair_levels = 0;
    uint32_t ypair_entries = 0;
};
GridLayout grid_layout(const NeuralModel& model, uint64_t max_bytes = std::numeric_limits<uint64_t>::max());

// The grid buffer's contents (throws nbvh::Error if the model's grid does not hold its levels' entries).
PackedGrid pack_grid(const NeuralModel& model, uint64_t max_bytes = std::numeric_limits<uint64_t>::max());
// The extension word after the packed levels (NB_LEVEL_YPAIR_WORD).
uvec4 ypair_word(const PackedGrid& grid);

} // namespace nbvh::render
