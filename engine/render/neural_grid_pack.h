// The hash grid as the GPU reads it: the model's fp16 entries packed two halves per word
// (pack_halves), followed by a y-pair table of its leading dense levels (shared/hashgrid.h, "Y-pair
// table"): entry i of such a level next to the entry of its +y neighbour, 16 bytes, so that the split
// query's gather reads the two corners c and c|2 of a cell in one load (lib/neural_grid.glsl). The
// level buffer gets one more 16-byte word after the levels: (y-pair base in 16-byte words, y-paired
// levels, 0, 0).
#pragma once
#include <cstdint>
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
// The grid buffer's contents (throws nbvh::Error if the model's grid does not hold its levels' entries).
PackedGrid pack_grid(const NeuralModel& model);
// The extension word after the packed levels (NB_LEVEL_YPAIR_WORD).
uvec4 ypair_word(const PackedGrid& grid);
// Bytes of pack_grid's words without building them (memory estimates).
uint64_t packed_grid_bytes(const NeuralModel& model);

} // namespace nbvh::render
