// .nbvh round trip, golden bytes, and rejection of truncated, corrupted, foreign and hostile files.
#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "engine/core/error.h"
#include "engine/neural/fp16.h"
#include "shaders/shared/neural_gpu.h"
#include "shaders/shared/neural_occupancy.h"
#include "tests/model/tiny_model.h"
#include "tests/support/test_support.h"

namespace nbvh {
namespace {

using test::make_tiny_model;
using test::refresh_checksums;

// Expects parse_model to throw nbvh::Error whose message contains `needle`.
void expect_rejected(const std::vector<uint8_t>& bytes, const std::string& needle) {
    try {
        parse_model(bytes, "m.nbvh");
        ADD_FAILURE() << "accepted a bad file (expected: " << needle << ")";
    } catch (const Error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(needle), std::string::npos) << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << "one line: " << what;
        EXPECT_EQ(what.rfind("m.nbvh: ", 0), 0u) << "names the file: " << what;
    }
}

template <class F> void expect_throw_containing(F&& f, const std::string& needle) {
    try {
        f();
        ADD_FAILURE() << "no error (expected: " << needle << ")";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
}

template <class T> void poke(std::vector<uint8_t>& b, size_t at, T v) { std::memcpy(b.data() + at, &v, sizeof(T)); }

size_t section_offset(const std::vector<uint8_t>& b, const std::string& id) {
    for (const auto& s : test::section_locations(b))
        if (s.id == id) return s.offset;
    ADD_FAILURE() << "no section " << id;
    return 0;
}

// `b` with the u32 at `at` replaced and the checksums made valid again.
std::vector<uint8_t> edited(const std::vector<uint8_t>& b, size_t at, uint32_t value) {
    std::vector<uint8_t> c = b;
    poke(c, at, value);
    refresh_checksums(c);
    return c;
}

// `b` whose section table gives section `id` `size` bytes (checksums valid again).
std::vector<uint8_t> resized_section(const std::vector<uint8_t>& b, const std::string& id, uint64_t size) {
    std::vector<uint8_t> c = b;
    size_t k = 0;
    for (const auto& s : test::section_locations(b)) {
        if (s.id == id) poke<uint64_t>(c, 32 + 32 * k + 16, size);
        ++k;
    }
    refresh_checksums(c);
    return c;
}

TEST(ModelFile, RoundTrip) {
    const NeuralModel a = make_tiny_model();
    const NeuralModel b = parse_model(serialize_model(a));
    EXPECT_EQ(b.cfg.log2_hash_size, 4u);
    EXPECT_EQ(b.cfg.per_level_scale, a.cfg.per_level_scale);
    ASSERT_EQ(b.levels.size(), a.levels.size());
    for (size_t i = 0; i < a.levels.size(); ++i) {
        EXPECT_EQ(b.levels[i].offset, a.levels[i].offset);
        EXPECT_EQ(b.levels[i].scale, a.levels[i].scale);
        EXPECT_EQ(b.levels[i].hashed, a.levels[i].hashed);
    }
    ASSERT_EQ(b.assets.size(), 1u);
    EXPECT_EQ(b.assets[0].name, "tiny_asset");
    EXPECT_EQ(b.encoding_box.hi, glm::vec3(1.0f));
    EXPECT_EQ(b.lod_count, 2u);
    EXPECT_EQ(b.lod_node_counts, (std::vector<uint32_t>{5, 3}));
    ASSERT_EQ(b.nodes.size(), 5u);
    for (size_t i = 0; i < 5; ++i) {
        EXPECT_EQ(b.nodes[i].bounds.lo, a.nodes[i].bounds.lo);
        EXPECT_EQ(b.nodes[i].left, a.nodes[i].left);
        EXPECT_EQ(b.nodes[i].base_node, a.nodes[i].base_node);
        EXPECT_EQ(b.nodes[i].lod, a.nodes[i].lod);
        EXPECT_EQ(b.nodes[i].final_leaf, a.nodes[i].final_leaf);
        EXPECT_EQ(b.nodes[i].depth, a.nodes[i].depth);
        EXPECT_EQ(b.nodes[i].parent, a.nodes[i].parent);
    }
    EXPECT_EQ(b.mlp, a.mlp);
    EXPECT_EQ(b.grid, a.grid);
    EXPECT_EQ(b.meta.steps, 10000u);
    EXPECT_EQ(b.meta.final_loss, 0.125f);
    EXPECT_EQ(b.meta.seconds, 61.5);
    EXPECT_EQ(b.meta.backend, "cpu");
    EXPECT_EQ(b.meta.source, "scenes/tiny.gltf");
    EXPECT_EQ(b.meta.source_hash, 0x0123456789abcdefull);
    EXPECT_EQ(b.meta.created_unix, 1718000000);
    EXPECT_EQ(b.meta.source_triangles, 1000u);
    EXPECT_EQ(b.meta.source_vertices, 600u);
    EXPECT_EQ(b.meta.split_scaling, 2.5f);
    EXPECT_EQ(b.tree().node_count_at(1), 3u);
}

TEST(ModelFile, SaveIsAtomicAndLoadReadsItBack) {
    const auto dir = test::temp_dir("model_save");
    const auto path = dir / "tiny.nbvh";
    save_model(path, make_tiny_model());
    save_model(path, make_tiny_model()); // replacing an existing model is fine
    EXPECT_EQ(load_model(path).nodes.size(), 5u);
    size_t files = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir)) files += e.is_regular_file();
    EXPECT_EQ(files, 1u) << "no temporary file left behind";
    // An invalid model is refused and nothing is written.
    NeuralModel bad = make_tiny_model();
    bad.mlp[3] = 0x7C00; // +inf
    EXPECT_THROW(save_model(dir / "bad.nbvh", bad), Error);
    EXPECT_FALSE(std::filesystem::exists(dir / "bad.nbvh"));
    EXPECT_THROW(load_model(dir / "missing.nbvh"), Error);
    EXPECT_THROW(load_model(dir), Error);
}

// Pins the format: any change to the byte layout must bump MODEL_FORMAT_VERSION and this test.
TEST(ModelFile, GoldenBytes) {
    const std::vector<uint8_t> b = serialize_model(make_tiny_model());
    const uint8_t head[16] = {'N', 'B', 'V', 'H', 5, 0, 0, 0, 8, 0, 0, 0, 0, 0, 0, 0};
    ASSERT_GE(b.size(), 16u);
    EXPECT_EQ(std::memcmp(b.data(), head, 16), 0);
    std::vector<std::string> ids;
    for (const auto& s : test::section_locations(b)) ids.push_back(s.id);
    EXPECT_EQ(ids, (std::vector<std::string>{"CONF", "ASST", "LEVL", "LODS", "NODE", "MLP ", "GRID", "META"}));
    // CONF: levels 8, features 4, base res 8, scale 2.0f, log2 T 4, points 3, width 64, hidden 4,
    // outputs 8, LoDs 2 (all u32 but the f32 scale).
    const uint32_t conf[10] = {8, 4, 8, 0x40000000u, 4, 3, 64, 4, 8, 2};
    EXPECT_EQ(std::memcmp(b.data() + section_offset(b, "CONF"), conf, 40), 0);
    // NODE: count 5, 0, then the root: bounds (0,0,0)-(1,1,1), left 1, base node 0, LoD code 0xFF (interior
    // at every LoD), flags 0, padding.
    const uint32_t node_head[2 + 10] = {5, 0, 0, 0, 0, 0x3f800000u, 0x3f800000u, 0x3f800000u, 1, 0, 0xFFu, 0};
    EXPECT_EQ(std::memcmp(b.data() + section_offset(b, "NODE"), node_head, sizeof(node_head)), 0);
    EXPECT_EQ(b.size(), 40984u);
    EXPECT_EQ(fnv1a64(b.data(), b.size()), 0x300a879778e67b84ull) << std::hex << fnv1a64(b.data(), b.size());
}

// Occupancy masks (version 3): an optional section after META, written only when the model has masks,
// read back exactly; refused in an older version's file, with the wrong node or word count, or cut short.
TEST(ModelFile, OccupancyMasksAreAnOptionalSection) {
    NeuralModel a = make_tiny_model();
    const std::vector<uint8_t> plain = serialize_model(a);
    for (const auto& s : test::section_locations(plain)) EXPECT_NE(s.id, "OCCU");
    EXPECT_TRUE(parse_model(plain).occupancy.empty());
    const uint64_t plain_bytes = model_gpu_bytes(a);
    a.occupancy.resize(a.nodes.size() * NB_OCC_WORDS);
    for (size_t i = 0; i < a.occupancy.size(); ++i) a.occupancy[i] = uint32_t(i * 2654435761u);
    EXPECT_EQ(model_gpu_bytes(a) - plain_bytes, a.nodes.size() * NB_OCC_WORDS * 4);
    const std::vector<uint8_t> b = serialize_model(a);
    std::vector<std::string> ids;
    for (const auto& s : test::section_locations(b)) ids.push_back(s.id);
    EXPECT_EQ(ids, (std::vector<std::string>{"CONF", "ASST", "LEVL", "LODS", "NODE", "MLP ", "GRID", "META", "OCCU"}));
    const uint32_t head[4] = {5, NB_OCC_WORDS, a.occupancy[0], a.occupancy[1]};
    EXPECT_EQ(std::memcmp(b.data() + section_offset(b, "OCCU"), head, sizeof(head)), 0);
    EXPECT_EQ(parse_model(b).occupancy, a.occupancy);
    expect_rejected(edited(b, 4, 2), "occupancy masks need format version 3");
    expect_rejected(edited(b, section_offset(b, "OCCU"), 4), "4 nodes x 16 words, the model has 5 nodes");
    expect_rejected(edited(b, section_offset(b, "OCCU") + 4, 64), "5 nodes x 64 words, the model has 5 nodes x 16");
    // A shorter payload (the section table says 8 bytes less).
    EXPECT_THROW(parse_model(resized_section(b, "OCCU", 8 + 5 * NB_OCC_WORDS * 4 - 8), "m.nbvh"), Error);
}

// Node materials (version 4): an optional section after OCCU (when present), one word per node, read
// back exactly; refused in an older version's file, with the wrong node count, a non-zero reserved
// field or a short payload; counted in the model's GPU bytes.
TEST(ModelFile, NodeMaterialsAreAnOptionalSection) {
    NeuralModel a = make_tiny_model();
    for (const auto& s : test::section_locations(serialize_model(a))) EXPECT_NE(s.id, "MATL");
    const uint64_t plain_bytes = model_gpu_bytes(a);
    a.occupancy.assign(a.nodes.size() * NB_OCC_WORDS, 0xFFFFFFFFu);
    for (uint32_t i = 0; i < a.nodes.size(); ++i) a.node_materials.push_back(nb_pack_node_material(0.1f * i, 1.0f - 0.2f * i));
    EXPECT_EQ(model_gpu_bytes(a) - plain_bytes, a.nodes.size() * (NB_OCC_WORDS + 1) * 4);
    const std::vector<uint8_t> b = serialize_model(a);
    std::vector<std::string> ids;
    for (const auto& s : test::section_locations(b)) ids.push_back(s.id);
    EXPECT_EQ(ids, (std::vector<std::string>{"CONF", "ASST", "LEVL", "LODS", "NODE", "MLP ", "GRID", "META", "OCCU", "MATL"}));
    const uint32_t head[4] = {5, 0, a.node_materials[0], a.node_materials[1]};
    EXPECT_EQ(std::memcmp(b.data() + section_offset(b, "MATL"), head, sizeof(head)), 0);
    const NeuralModel back = parse_model(b);
    EXPECT_EQ(back.node_materials, a.node_materials);
    EXPECT_EQ(back.occupancy, a.occupancy);
    expect_rejected(edited(b, 4, 3), "node materials need format version 4");
    const NeuralModel v4 = parse_model(edited(b, 4, 4)); // a version-4 file (no fits) still loads
    EXPECT_EQ(v4.node_materials, a.node_materials);
    EXPECT_TRUE(v4.material_fits.empty());
    EXPECT_EQ(v4.file_version, 4u);
    expect_rejected(edited(b, section_offset(b, "MATL"), 4), "4 nodes, the model has 5");
    expect_rejected(edited(b, section_offset(b, "MATL") + 4, 1), "reserved field is not zero");
    EXPECT_THROW(parse_model(resized_section(b, "MATL", 8 + 5 * 4 - 4), "m.nbvh"), Error);
}

// Material fits (version 5): an optional section after MATL, NB_NODE_FIT_WORDS words of two fp16 per
// node, read back exactly; refused in an older version's file, with the wrong node or word count, a
// non-finite coefficient or a short payload; counted in the model's GPU bytes.
TEST(ModelFile, MaterialFitsAreAnOptionalSection) {
    NeuralModel a = make_tiny_model();
    for (const auto& s : test::section_locations(serialize_model(a))) EXPECT_NE(s.id, "MFIT");
    const uint64_t plain_bytes = model_gpu_bytes(a);
    for (uint32_t i = 0; i < a.nodes.size(); ++i) a.node_materials.push_back(nb_pack_node_material(0.5f, 0.5f));
    for (uint32_t i = 0; i < a.nodes.size() * NB_NODE_FIT_WORDS; ++i)
        a.material_fits.push_back(uint32_t(float_to_half_bits(0.25f * i)) | uint32_t(float_to_half_bits(-2.0f)) << 16);
    EXPECT_EQ(model_gpu_bytes(a) - plain_bytes, a.nodes.size() * (1 + NB_NODE_FIT_WORDS) * 4);
    const std::vector<uint8_t> b = serialize_model(a);
    std::vector<std::string> ids;
    for (const auto& s : test::section_locations(b)) ids.push_back(s.id);
    EXPECT_EQ(ids, (std::vector<std::string>{"CONF", "ASST", "LEVL", "LODS", "NODE", "MLP ", "GRID", "META", "MATL", "MFIT"}));
    const uint32_t head[4] = {5, NB_NODE_FIT_WORDS, a.material_fits[0], a.material_fits[1]};
    EXPECT_EQ(std::memcmp(b.data() + section_offset(b, "MFIT"), head, sizeof(head)), 0);
    const NeuralModel back = parse_model(b);
    EXPECT_EQ(back.material_fits, a.material_fits);
    EXPECT_EQ(back.node_materials, a.node_materials);
    expect_rejected(edited(b, 4, 4), "material fits need format version 5");
    expect_rejected(edited(b, section_offset(b, "MFIT"), 4), "4 nodes x 5 words, the model has 5 nodes x 5");
    expect_rejected(edited(b, section_offset(b, "MFIT") + 4, 1), "5 nodes x 1 words, the model has 5 nodes x 5");
    expect_rejected(edited(b, section_offset(b, "MFIT") + 8 + 4 * 7, 0x7C00u), "word 7 is not valid"); // +inf
    expect_rejected(edited(b, section_offset(b, "MFIT") + 8, 0x7E000000u), "word 0 is not valid");    // NaN high half
    EXPECT_THROW(parse_model(resized_section(b, "MFIT", 8 + 5 * NB_NODE_FIT_WORDS * 4 - 4), "m.nbvh"), Error);
}

TEST(ModelFile, TruncationAnywhereIsRejected) {
    const std::vector<uint8_t> b = serialize_model(make_tiny_model());
    std::vector<size_t> cuts{0, 1, 3, 4, 16, 31, 32, 33, 64, 100};
    for (const auto& s : test::section_locations(b)) {
        cuts.push_back(s.offset);
        cuts.push_back(s.offset + 1);
        cuts.push_back(s.offset + s.size / 2);
        cuts.push_back(s.offset + s.size - 1);
        cuts.push_back(s.offset + s.size);
    }
    std::mt19937 rng(3);
    for (int i = 0; i < 200; ++i) cuts.push_back(rng() % b.size());
    for (size_t cut : cuts) {
        if (cut >= b.size()) continue;
        std::vector<uint8_t> t(b.begin(), b.begin() + cut);
        EXPECT_THROW(parse_model(t), Error) << "cut at " << cut;
    }
    expect_rejected(std::vector<uint8_t>(b.begin(), b.end() - 8), "truncated");
    std::vector<uint8_t> longer = b;
    longer.push_back(0);
    expect_rejected(longer, "trailing data");
}

TEST(ModelFile, FlippedBytesInEverySectionAreRejected) {
    const std::vector<uint8_t> b = serialize_model(make_tiny_model());
    for (const auto& s : test::section_locations(b)) {
        for (size_t at : {s.offset, s.offset + s.size / 2, s.offset + s.size - 1}) {
            std::vector<uint8_t> c = b;
            c[at] ^= 0x10;
            expect_rejected(c, "section '" + s.id + "': checksum mismatch");
        }
    }
    for (size_t at : {5, 9, 17, 40, 70}) {
        std::vector<uint8_t> c = b;
        c[at] ^= 0x01;
        EXPECT_THROW(parse_model(c), Error) << "header byte " << at;
    }
}

TEST(ModelFile, ForeignFilesAreRejected) {
    std::vector<uint8_t> b = serialize_model(make_tiny_model());
    std::vector<uint8_t> c = b;
    c[0] = 'X';
    expect_rejected(c, "not an nbvh model (bad magic)");
    expect_rejected({}, "not an nbvh model (file too short)");
    c = b;
    poke<uint32_t>(c, 4, MODEL_FORMAT_VERSION + 1);
    refresh_checksums(c);
    expect_rejected(c, "unsupported model format version " + std::to_string(MODEL_FORMAT_VERSION + 1));
    // An official N-BVH tree file (u64 N, u64 1, N x 40 bytes, u64 0) of 3 nodes.
    std::vector<uint8_t> official(16 + 3 * 40 + 8, 0);
    poke<uint64_t>(official, 0, 3);
    poke<uint64_t>(official, 8, 1);
    expect_rejected(official, "official N-BVH tree file?");
}

TEST(ModelFile, HostileCountsAreRejectedBeforeAllocation) {
    const std::vector<uint8_t> b = serialize_model(make_tiny_model());
    auto edited = [&](const std::string& id, size_t rel, auto value) {
        std::vector<uint8_t> c = b;
        poke(c, section_offset(c, id) + rel, value);
        refresh_checksums(c);
        return c;
    };
    expect_rejected(edited("NODE", 0, uint32_t(0xFFFFFFFF)), "node count 4294967295 exceeds the section size");
    expect_rejected(edited("GRID", 0, uint64_t(1) << 62), "values, the level table needs");
    expect_rejected(edited("MLP ", 0, uint32_t(0x7FFFFFFF)), "weights, expected");
    expect_rejected(edited("ASST", 24, uint32_t(0xFFFFFFF0)), "asset count 4294967280 out of range");
    expect_rejected(edited("ASST", 32, uint32_t(0xFFFFFFF0)), "asset name length");
    expect_rejected(edited("ASST", 64, uint32_t(0xFFFFFFF0)), "node path count 4294967280 exceeds the section");
    expect_rejected(edited("LODS", 0, uint32_t(1000000)), "node counts for 2 LoDs");
    expect_rejected(edited("CONF", 36, uint32_t(200)), "LoD count 200 out of range");
    std::vector<uint8_t> c = b;
    poke<uint32_t>(c, 8, 0x10000000); // section count
    refresh_checksums(c);
    expect_rejected(c, "section count");
    c = b;
    poke<uint64_t>(c, 32 + 8, uint64_t(1) << 60); // first section's offset
    refresh_checksums(c);
    expect_rejected(c, "outside the file");
}

TEST(ModelFile, BadContentIsRejected) {
    const std::vector<uint8_t> b = serialize_model(make_tiny_model());
    auto edited = [&](const std::string& id, size_t rel, auto value) {
        std::vector<uint8_t> c = b;
        poke(c, section_offset(c, id) + rel, value);
        refresh_checksums(c);
        return c;
    };
    const size_t node1 = 8 + 40; // node 1 record in NODE
    expect_rejected(edited("NODE", node1, std::numeric_limits<float>::quiet_NaN()), "non-finite bounds");
    expect_rejected(edited("NODE", node1, 5.0f), "empty bounds");
    expect_rejected(edited("NODE", 8 + 24, uint32_t(4)), "child index 4 out of range"); // root's left
    expect_rejected(edited("NODE", 8 + 24, uint32_t(0)), "child index 0 out of range"); // cycle
    expect_rejected(edited("NODE", 8 + 32, uint8_t(7)), "LoD code 7");
    expect_rejected(edited("NODE", 8 + 33, uint8_t(0x80)), "unknown flags");
    expect_rejected(edited("LODS", 4, uint32_t(7)), "LoD 0 has 5 nodes, the table says 7");
    expect_rejected(edited("LEVL", 8 + 32 * 3 + 4, uint32_t(99)), "section 'LEVL'");
    expect_rejected(edited("LEVL", 8 + 32 * 2 + 12, 3.25f), "level 2 does not match");
    expect_rejected(edited("MLP ", 8 + 2 * 17, uint16_t(0x7E00)), "weight value 17 is not finite");
    expect_rejected(edited("GRID", 8, uint16_t(0xFC00)), "grid value 0 is not finite");
    expect_rejected(edited("ASST", 0, std::numeric_limits<float>::infinity()), "encoding box is not finite");
    expect_rejected(edited("ASST", 12, 0.0f), "encoding box has no volume");
    expect_rejected(edited("ASST", 36, uint8_t(27)), "control character"); // ESC in the name
    // The asset table: root (u32 at 84) a node, placement (scale f32 at 92) finite and positive.
    expect_rejected(edited("ASST", 84, uint32_t(99)), "asset 'tiny_asset' root 99 is not a node");
    expect_rejected(edited("ASST", 92, -1.0f), "non-finite or non-positive placement");
    expect_rejected(edited("ASST", 96, std::numeric_limits<float>::quiet_NaN()), "non-finite or non-positive placement");
    expect_rejected(edited("META", 8, -1.0), "non-finite or negative");
    expect_rejected(edited("META", 76, uint32_t(0xFFFF)), "backend length");
    expect_rejected(edited("CONF", 24, uint32_t(32)), "unsupported mlp_width 32");
}

TEST(ModelFile, ChessReferenceIsTheOfficialFormat) {
    NBVH_REQUIRE_SHARED();
    const auto path = test::scenes_dir() / "chess_nbvh/reference/nodes_32940_hash_18_lvl_8_tsteps_10000.nbvh";
    try {
        load_model(path);
        ADD_FAILURE() << "the official file was accepted as an nbvh model";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("official N-BVH tree file?"), std::string::npos) << e.what();
    }
    const std::vector<NbvhNode> nodes = import_official_tree(path);
    EXPECT_EQ(nodes.size(), 25249u); // notes §10
    const NbvhTree tree = NbvhTree::from_nodes(nodes, 1);
    EXPECT_EQ(tree.leaf_count(), 12519u + 106u);
    size_t finals = 0;
    uint32_t min_leaf_depth = 999;
    for (uint32_t leaf : tree.leaves()) {
        finals += tree.node(leaf).final_leaf;
        min_leaf_depth = std::min(min_leaf_depth, tree.node(leaf).depth);
    }
    EXPECT_EQ(finals, 106u);
    EXPECT_EQ(min_leaf_depth, 10u);
    EXPECT_EQ(tree.max_depth(), 21u);
}

// A version-1 file (before the asset table: ASST = encoding box + one asset name) still loads, as one
// asset with root 0, identity placement and unknown fingerprints.
TEST(ModelFile, Version1FilesStillLoad) {
    const std::vector<uint8_t> v2 = serialize_model(make_tiny_model());
    std::vector<std::vector<uint8_t>> payloads;
    std::vector<std::string> ids;
    for (const auto& sec : test::section_locations(v2)) {
        ids.push_back(sec.id);
        std::vector<uint8_t> p(v2.begin() + long(sec.offset), v2.begin() + long(sec.offset + sec.size));
        if (sec.id == "ASST") {
            p.resize(24); // the encoding box
            const std::string name = "old_asset";
            const uint32_t len = uint32_t(name.size());
            p.insert(p.end(), reinterpret_cast<const uint8_t*>(&len), reinterpret_cast<const uint8_t*>(&len) + 4);
            p.insert(p.end(), name.begin(), name.end());
        }
        payloads.push_back(std::move(p));
    }
    std::vector<uint8_t> v1(v2.begin(), v2.begin() + long(32 + 32 * ids.size()));
    poke<uint32_t>(v1, 4, 1);
    for (size_t k = 0; k < ids.size(); ++k) {
        v1.resize((v1.size() + 7) & ~size_t(7), 0);
        poke<uint64_t>(v1, 32 + 32 * k + 8, v1.size());
        poke<uint64_t>(v1, 32 + 32 * k + 16, payloads[k].size());
        v1.insert(v1.end(), payloads[k].begin(), payloads[k].end());
    }
    v1.resize((v1.size() + 7) & ~size_t(7), 0);
    poke<uint64_t>(v1, 16, v1.size());
    refresh_checksums(v1);
    const NeuralModel m = parse_model(v1, "old.nbvh");
    EXPECT_EQ(m.file_version, 1u);
    EXPECT_EQ(parse_model(v2).file_version, MODEL_FORMAT_VERSION);
    ASSERT_EQ(m.assets.size(), 1u);
    EXPECT_EQ(m.assets[0].name, "old_asset");
    EXPECT_EQ(m.assets[0].material, "");
    EXPECT_EQ(m.assets[0].root, 0u);
    EXPECT_EQ(m.assets[0].scale, 1.0f);
    EXPECT_EQ(m.assets[0].geometry_hash, 0u);
    EXPECT_EQ(m.nodes.size(), make_tiny_model().nodes.size());
}

// Several assets: their subtrees must be disjoint (a root inside another asset's subtree, or shared, is
// refused when saving as when loading), names unique; a valid table round-trips.
TEST(ModelFile, AssetTable) {
    NeuralModel m = make_tiny_model();
    ModelAsset second = m.assets[0];
    second.name = "second";
    second.root = 1;
    m.assets.push_back(second);
    expect_throw_containing([&] { serialize_model(m); }, "asset 'second' lies inside asset 'tiny_asset'");
    m.assets[1].root = 0;
    expect_throw_containing([&] { serialize_model(m); }, "share a root");
    // Root 0's children (1, 2) as two assets: disjoint.
    m.assets[0].root = 1;
    m.assets[1].root = 2;
    m.assets[1].node_paths = {"a", "b"};
    m.assets[1].geometry_hash = 0x1234;
    m.assets[1].scale = 0.5f;
    m.assets[1].offset = glm::vec3(1.0f, 2.0f, 3.0f);
    const NeuralModel r = parse_model(serialize_model(m));
    ASSERT_EQ(r.assets.size(), 2u);
    EXPECT_EQ(r.assets[1].name, "second");
    EXPECT_EQ(r.assets[1].root, 2u);
    EXPECT_EQ(r.assets[1].node_paths, (std::vector<std::string>{"a", "b"}));
    EXPECT_EQ(r.assets[1].geometry_hash, 0x1234u);
    EXPECT_EQ(r.assets[1].scale, 0.5f);
    EXPECT_EQ(r.assets[1].offset, glm::vec3(1.0f, 2.0f, 3.0f));
    m.assets[1].name = "tiny_asset";
    expect_throw_containing([&] { serialize_model(m); }, "appears twice");
}

} // namespace
} // namespace nbvh
