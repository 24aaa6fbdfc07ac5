// A tiny model with fixed content (golden bytes, round trip, corruption and fuzz tests), and a helper
// that recomputes a file's checksums after a deliberate edit (so tests reach the checks behind them).
#pragma once
#include <cmath>
#include <cstring>
#include <span>
#include <vector>

#include "engine/neural/fp16.h"
#include "engine/neural/level_table.h"
#include "engine/neural/model_file.h"
#include "engine/neural/model_sections.h"
#include "shaders/shared/mlp.h"
#include "tests/model/synthetic_bvh.h"

namespace nbvh::test {

// 8 levels with a 2^4 hash table: 8 x 16 entries x 4 features = 512 grid halves; the full MLP.
// Tree: root split, LoD 1 registered, then one child split: LoD 1 = 3 nodes, LoD 0 = 5 nodes.
inline NeuralModel make_tiny_model() {
    NeuralModel m;
    m.cfg.log2_hash_size = 4;
    m.levels = neural::make_level_table(m.cfg);
    m.assets.resize(1);
    m.assets[0].name = m.assets[0].mesh = "tiny_asset";
    m.encoding_box.lo = glm::vec3(0.0f);
    m.encoding_box.hi = glm::vec3(1.0f);
    static const Bvh base = make_complete_bvh(3);
    NbvhTree tree(base, 2);
    tree.split(0);
    tree.register_lod();
    tree.split(1);
    tree.finish_lods();
    set_tree(m, tree);
    m.mlp.resize(NB_MLP_WEIGHT_COUNT);
    for (size_t i = 0; i < m.mlp.size(); ++i) m.mlp[i] = float_to_half_bits(0.01f * float(int(i % 201) - 100));
    m.grid.resize(neural::level_table_entries(m.levels) * m.cfg.grid_features);
    for (size_t i = 0; i < m.grid.size(); ++i) m.grid[i] = float_to_half_bits(1e-4f * float(int(i % 21) - 10));
    m.meta.steps = 10000;
    m.meta.final_loss = 0.125f;
    m.meta.seconds = 61.5;
    m.meta.batch_size = 262144;
    m.meta.backend = "cpu";
    m.meta.source = "scenes/tiny.gltf";
    m.meta.source_hash = 0x0123456789abcdefull;
    m.meta.created_unix = 1718000000;
    m.meta.source_triangles = 1000;
    m.meta.source_vertices = 600;
    m.meta.splitting_interval = 40;
    m.meta.last_split_iteration = 3000;
    m.meta.start_split_num = 1;
    m.meta.split_scaling = 2.5f;
    m.meta.split_interval_scaling = 2.0f;
    return m;
}

struct SectionLocation {
    std::string id;
    size_t entry;   // offset of its section-table entry
    size_t offset;  // payload offset
    size_t size;
};

inline std::vector<SectionLocation> section_locations(std::span<const uint8_t> file) {
    uint32_t count;
    std::memcpy(&count, file.data() + 8, 4);
    std::vector<SectionLocation> out;
    for (uint32_t i = 0; i < count; ++i) {
        const size_t e = model_io::HEADER_BYTES + i * model_io::SECTION_ENTRY_BYTES;
        uint64_t off, size;
        std::memcpy(&off, file.data() + e + 8, 8);
        std::memcpy(&size, file.data() + e + 16, 8);
        out.push_back({std::string(reinterpret_cast<const char*>(file.data() + e), 4), e, size_t(off), size_t(size)});
    }
    return out;
}

// Recomputes every section checksum and the header checksum in place (the table must be in range).
inline void refresh_checksums(std::vector<uint8_t>& file) {
    uint32_t count;
    std::memcpy(&count, file.data() + 8, 4);
    if (file.size() < model_io::HEADER_BYTES + size_t(count) * model_io::SECTION_ENTRY_BYTES) return;
    for (const SectionLocation& s : section_locations(file)) {
        if (s.offset > file.size() || s.size > file.size() - s.offset) continue;
        const uint64_t h = fnv1a64(file.data() + s.offset, s.size);
        std::memcpy(file.data() + s.entry + 24, &h, 8);
    }
    const uint64_t h = model_io::header_checksum(file.data(), count);
    std::memcpy(file.data() + 24, &h, 8);
}

} // namespace nbvh::test
