#include "tests/fuzz/model_seeds.h"

#include <algorithm>
#include <cstring>

#include "engine/neural/level_table.h"
#include "shaders/shared/neural_gpu.h"
#include "shaders/shared/neural_occupancy.h"
#include "tests/model/tiny_model.h"

namespace nbvh::fuzz {
namespace {

std::vector<uint8_t> bytes_of(const NeuralModel& m) { return serialize_model(m); }

// The tiny model with another hash-table size (level table and grid follow it).
NeuralModel with_hash_log2(NeuralModel m, uint32_t log2_hash_size) {
    m.cfg.log2_hash_size = log2_hash_size;
    m.levels = neural::make_level_table(m.cfg);
    m.grid.assign(neural::level_table_entries(m.levels) * m.cfg.grid_features, float_to_half_bits(0.5f));
    return m;
}

// The tiny model with the tree cut from a depth-`depth` synthetic BVH: each round splits every splittable
// leaf, then registers a LoD (the last round's cut is LoD 0).
NeuralModel with_tree(NeuralModel m, uint32_t depth, uint32_t lods, uint32_t rounds) {
    static std::vector<Bvh> bases; // NbvhTree keeps a pointer to its base while splitting
    bases.push_back(test::make_complete_bvh(depth));
    NbvhTree tree(bases.back(), lods);
    for (uint32_t r = 0; r < rounds; ++r) {
        std::vector<uint32_t> leaves = tree.leaves();
        tree.split_many(leaves);
        if (tree.registered_lods() + 1 < lods) tree.register_lod();
    }
    tree.finish_lods();
    set_tree(m, tree);
    m.assets.resize(1);
    m.assets[0].root = 0;
    return m;
}

// The tiny model with its optional sections: occupancy masks (OCCU), node materials (MATL) and
// material fits (MFIT: fp16 0.5 and -1.0 in every word).
NeuralModel with_masks_and_materials(NeuralModel m) {
    m.occupancy.assign(m.nodes.size() * NB_OCC_WORDS, 0x0F0F0F0Fu);
    for (uint32_t i = 0; i < m.nodes.size(); ++i) m.node_materials.push_back(nb_pack_node_material(0.2f * i, 1.0f - 0.1f * i));
    m.material_fits.assign(m.nodes.size() * NB_NODE_FIT_WORDS, 0xBC003800u);
    return m;
}

} // namespace

std::vector<Seed> model_seeds() {
    std::vector<Seed> out;
    const NeuralModel tiny = test::make_tiny_model();
    const std::vector<uint8_t> tiny_bytes = bytes_of(tiny);
    out.push_back({"valid_tiny.nbvh", tiny_bytes});
    {
        // Two assets on the root's children (disjoint subtrees), with node paths and a placement.
        NeuralModel m = tiny;
        m.assets.push_back(m.assets[0]);
        m.assets[0].root = 1;
        m.assets[1].name = "second";
        m.assets[1].material = "brick";
        m.assets[1].root = 2;
        m.assets[1].node_paths = {"scene/a", "scene/b"};
        m.assets[1].geometry_hash = 0x1234;
        m.assets[1].material_hash = 0x5678;
        m.assets[1].scale = 0.5f;
        m.assets[1].offset = glm::vec3(1.0f, 2.0f, 3.0f);
        out.push_back({"valid_two_assets.nbvh", bytes_of(m)});
    }
    out.push_back({"valid_hash6.nbvh", bytes_of(with_hash_log2(tiny, 6))});
    out.push_back({"valid_one_lod.nbvh", bytes_of(with_tree(tiny, 3, 1, 2))});
    out.push_back({"valid_four_lods.nbvh", bytes_of(with_tree(tiny, 5, 4, 4))});
    out.push_back({"valid_root_only.nbvh", bytes_of(with_tree(tiny, 2, 1, 0))});
    out.push_back({"valid_masks_materials.nbvh", bytes_of(with_masks_and_materials(tiny))});

    // Damaged copies of the tiny model.
    auto cut = [&](size_t n) { return std::vector<uint8_t>(tiny_bytes.begin(), tiny_bytes.begin() + long(n)); };
    out.push_back({"truncated_header.nbvh", cut(20)});
    out.push_back({"truncated_table.nbvh", cut(model_io::HEADER_BYTES + 2 * model_io::SECTION_ENTRY_BYTES)});
    out.push_back({"truncated_half.nbvh", cut(tiny_bytes.size() / 2)});
    out.push_back({"truncated_last_byte.nbvh", cut(tiny_bytes.size() - 1)});
    for (const test::SectionLocation& s : test::section_locations(tiny_bytes)) {
        if (s.size == 0) continue;
        std::string id = s.id;
        for (char& c : id) c = c == ' ' ? '_' : c;
        // The first word of a section is a count or a size: flip its top bit and a low bit.
        std::vector<uint8_t> b = tiny_bytes;
        b[s.offset + std::min<size_t>(3, s.size - 1)] ^= 0x80;
        b[s.offset] ^= 0x01;
        test::refresh_checksums(b);
        out.push_back({"bitflip_" + id + ".nbvh", b});
        // A flip in the middle of the payload, checksums left stale (checksum errors).
        b = tiny_bytes;
        b[s.offset + s.size / 2] ^= 0x10;
        out.push_back({"bitflip_" + id + "_stale_checksum.nbvh", b});
    }
    {
        // The official implementation's tree file (notes §10): 3 nodes, root with two leaf children.
        std::vector<uint8_t> official(16 + 3 * 40 + 8, 0);
        const uint64_t three = 3, one = 1, left = 1, none = 0xFFFFFFFFull, leaf_code = 2;
        std::memcpy(official.data(), &three, 8);
        std::memcpy(official.data() + 8, &one, 8);
        std::memcpy(official.data() + 16 + 24, &left, 8);
        for (int n = 1; n < 3; ++n) {
            std::memcpy(official.data() + 16 + 40 * n + 24, &none, 8);
            std::memcpy(official.data() + 16 + 40 * n + 32, &leaf_code, 8);
        }
        out.push_back({"official_tree.bin", official});
    }
    return out;
}

} // namespace nbvh::fuzz
