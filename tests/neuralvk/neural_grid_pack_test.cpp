// The grid buffer the GPU reads (engine/render/neural_grid_pack.h): the entries as the model holds them,
// then the y-pair table of the leading dense power-of-two levels (shared/hashgrid.h), whose entry i
// must hold the level's entries of vertex i and of its +y neighbour, as the row-major index with
// tcnn's aliasing and wrapping gives them (nb_grid_vertex_index), at every edge of the level.
#include "engine/core/error.h"
#include "engine/neural/level_table.h"
#include "engine/render/neural_grid_pack.h"

#include <gtest/gtest.h>

#include <random>

using namespace nbvh;
using namespace nbvh::render;

namespace {

NeuralModel model_with(uint32_t base_resolution, float per_level_scale, uint32_t log2_hash) {
    NeuralModel m;
    m.cfg.base_resolution = base_resolution;
    m.cfg.per_level_scale = per_level_scale;
    m.cfg.log2_hash_size = log2_hash;
    m.levels = neural::make_level_table(m.cfg);
    m.grid.resize(neural::level_table_entries(m.levels) * NB_GRID_FEATURES);
    std::mt19937 rng(7);
    for (uint16_t& h : m.grid) h = uint16_t(rng());
    return m;
}

// The 2 words of entry e of the packed buffer.
std::pair<uint32_t, uint32_t> entry_words(const PackedGrid& g, uint32_t e) { return {g.words[2 * e], g.words[2 * e + 1]}; }

} // namespace

TEST(NeuralGridPack, YPairLevelsAreTheLeadingDensePowerOfTwoOnes) {
    // Paper sizes: levels of 8, 16, 32, 64 vertices per axis are dense (8^3 .. 64^3 = 2^18 entries).
    EXPECT_EQ(ypair_level_count(model_with(8, 2.0f, 18).levels), 4u);
    EXPECT_EQ(ypair_level_count(model_with(8, 2.0f, 14).levels), 2u); // 32^3 > 2^14: hashed from level 2
    // Base resolution 6: 6^3 = 216 entries (not a power of two): the +y neighbour's index wraps by the
    // level size, not by 2^32, so no level qualifies even though the first ones are dense.
    const NeuralModel six = model_with(6, 2.0f, 18);
    EXPECT_EQ(six.levels[0].hashed, 0u);
    EXPECT_EQ(ypair_level_count(six.levels), 0u);
    const PackedGrid g = pack_grid(six);
    EXPECT_EQ(g.ypair_levels, 0u);
    EXPECT_EQ(g.ypair_entries, 0u);
    const GridLayout layout = grid_layout(six);
    EXPECT_EQ(g.words.size() * 4, layout.entry_bytes + layout.ypair_bytes);
    EXPECT_EQ(layout.ypair_bytes, 0u);
}

// A binding limit smaller than the whole buffer drops y-paired levels, finest first, until it fits
// (lavapipe's 128 MiB would not hold a 2^22 model's grid with its 2.4M-entry table otherwise).
TEST(NeuralGridPack, TableShrinksToTheBindingLimit) {
    const NeuralModel m = model_with(8, 2.0f, 18);
    const GridLayout whole = grid_layout(m);
    ASSERT_EQ(whole.ypair_levels, 4u);
    EXPECT_EQ(whole.ypair_bytes, uint64_t(512 + 4096 + 32768 + 262144) * 16);
    // Room for levels 0-2 only: level 3 (2^18 entries, 4 MiB of table) is dropped.
    const GridLayout three = grid_layout(m, whole.entry_bytes + whole.ypair_bytes - 1);
    EXPECT_EQ(three.ypair_levels, 3u);
    EXPECT_EQ(three.ypair_entries, 512u + 4096u + 32768u);
    const PackedGrid g = pack_grid(m, whole.entry_bytes + whole.ypair_bytes - 1);
    EXPECT_EQ(g.ypair_levels, 3u);
    EXPECT_EQ(g.words.size() * 4, three.entry_bytes + three.ypair_bytes);
    // No room at all: the entries alone (the renderer's own limit checks refuse a grid larger than that).
    EXPECT_EQ(grid_layout(m, whole.entry_bytes).ypair_levels, 0u);
    EXPECT_EQ(grid_layout(m, 1).ypair_levels, 0u);
}

TEST(NeuralGridPack, TableHoldsEachVertexAndItsYNeighbour) {
    // Paper sizes at 2^14 (2 levels paired) and 2^18 (4), and base resolution 3: 3^3 = 27 entries padded
    // to 32, a power of two, so the row-major index wraps by the padded size (level 0 paired; 6^3 is not).
    struct Case {
        uint32_t base, log2_hash, levels;
    };
    for (const Case& k : {Case{8, 14, 2}, Case{8, 18, 4}, Case{3, 14, 1}}) {
        const NeuralModel m = model_with(k.base, 2.0f, k.log2_hash);
        const PackedGrid g = pack_grid(m);
        ASSERT_EQ(g.ypair_levels, k.levels) << "base " << k.base << " hash 2^" << k.log2_hash;
        const GridLayout layout = grid_layout(m);
        ASSERT_EQ(g.words.size() * 4, layout.entry_bytes + layout.ypair_bytes);
        ASSERT_EQ(g.ypair_base * 4, (g.words.size() - size_t(g.ypair_entries) * 4)); // the table ends the buffer
        ASSERT_GE(g.ypair_base * 2, neural::level_table_entries(m.levels));          // after every entry
        const uvec4 w = ypair_word(g);
        EXPECT_EQ(w.x, g.ypair_base);
        EXPECT_EQ(w.y, g.ypair_levels);
        // The entries are the model's halves, unchanged.
        EXPECT_EQ(g.words[0], uint32_t(m.grid[0]) | (uint32_t(m.grid[1]) << 16));
        for (uint32_t l = 0; l < g.ypair_levels; ++l) {
            const GpuHashLevel& lv = m.levels[l];
            const uint32_t r = lv.resolution;
            // Every edge: the last vertex of a row and of a slab (y + 1 == res aliases into the next
            // slab, the last slab wraps by % size), cells at -1 (uint wrap, as tcnn), and random ones.
            std::vector<uvec3> cells = {{0, 0, 0},         {r - 1, r - 1, r - 1}, {r, r - 1, 0}, {0, r - 1, r - 1},
                                        {0xffffffffu, 0, 0}, {0, 0xffffffffu, 3}, {2, 5, 0xffffffffu}, {r, r, r}};
            std::mt19937 rng(l);
            for (int i = 0; i < 200; ++i) cells.push_back(uvec3(rng() % (r + 1), rng() % (r + 1), rng() % (r + 1)));
            for (const uvec3& c : cells) {
                const uint32_t here = lv.offset + nb_grid_vertex_index(lv, c.x, c.y, c.z);
                const uint32_t up = lv.offset + nb_grid_vertex_index(lv, c.x, c.y + 1, c.z);
                const size_t t = (size_t(g.ypair_base) + here) * 4;
                ASSERT_LT(t + 3, g.words.size());
                EXPECT_EQ(std::make_pair(g.words[t], g.words[t + 1]), entry_words(g, here)) << "level " << l;
                EXPECT_EQ(std::make_pair(g.words[t + 2], g.words[t + 3]), entry_words(g, up))
                    << "level " << l << " cell " << c.x << "," << c.y << "," << c.z;
            }
        }
    }
}

TEST(NeuralGridPack, GridSmallerThanItsLevelsIsRefused) {
    NeuralModel m = model_with(8, 2.0f, 14);
    m.grid.resize(100);
    EXPECT_THROW(pack_grid(m), Error);
}
