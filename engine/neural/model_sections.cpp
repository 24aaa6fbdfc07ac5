// Section encoding/decoding of the .nbvh format (layout table in README.md). Decoding validates
// everything before use: counts against the section size (before allocating), indices, floats.
#include "engine/neural/model_sections.h"

#include <cmath>

#include "engine/core/log.h"
#include "engine/neural/level_table.h"
#include "shaders/shared/mlp.h"
#include "shaders/shared/neural_gpu.h"
#include "shaders/shared/neural_occupancy.h"

namespace nbvh::model_io {

namespace {

constexpr char ID_CONF[4] = {'C', 'O', 'N', 'F'};
constexpr char ID_ASSET[4] = {'A', 'S', 'S', 'T'};
constexpr char ID_LEVELS[4] = {'L', 'E', 'V', 'L'};
constexpr char ID_LODS[4] = {'L', 'O', 'D', 'S'};
constexpr char ID_NODES[4] = {'N', 'O', 'D', 'E'};
constexpr char ID_MLP[4] = {'M', 'L', 'P', ' '};
constexpr char ID_GRID[4] = {'G', 'R', 'I', 'D'};
constexpr char ID_META[4] = {'M', 'E', 'T', 'A'};
constexpr char ID_OCC[4] = {'O', 'C', 'C', 'U'}; // optional, version 3
constexpr char ID_MATL[4] = {'M', 'A', 'T', 'L'}; // optional, version 4
constexpr char ID_MFIT[4] = {'M', 'F', 'I', 'T'}; // optional, version 5
constexpr const char* ALL_IDS[] = {ID_CONF, ID_ASSET, ID_LEVELS, ID_LODS, ID_NODES, ID_MLP, ID_GRID, ID_META, ID_OCC, ID_MATL, ID_MFIT};

constexpr uint8_t NODE_FLAG_FINAL = 1;

Section make(const char id[4], std::vector<uint8_t> payload) {
    Section s;
    std::memcpy(s.id, id, 4);
    s.payload = std::move(payload);
    return s;
}

bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool half_finite(uint16_t h) { return (h & 0x7C00u) != 0x7C00u; }

void put_halves(Writer& w, const std::vector<uint16_t>& v) {
    if (!v.empty()) w.bytes(v.data(), v.size() * 2);
}

// Reads `count` fp16 values after checking they fit (no allocation from an unchecked count).
std::vector<uint16_t> get_halves(Reader& r, uint64_t count, const char* what) {
    if (count > r.remaining() / 2)
        throw Error(strfmt("%s: %s count %llu exceeds the section size", r.where().c_str(), what,
                           (unsigned long long)count));
    std::vector<uint16_t> v(static_cast<size_t>(count));
    const auto bytes = r.take(size_t(count) * 2);
    if (count) std::memcpy(v.data(), bytes.data(), bytes.size());
    for (size_t i = 0; i < v.size(); ++i)
        if (!half_finite(v[i]))
            throw Error(strfmt("%s: %s value %zu is not finite (inf/NaN)", r.where().c_str(), what, i));
    return v;
}

void expect_end(const Reader& r) {
    if (r.remaining() != 0)
        throw Error(strfmt("%s: %zu unexpected bytes at the end", r.where().c_str(), r.remaining()));
}

void check_config(const NeuralConfig& c, const std::string& where) {
    auto need = [&](const char* field, uint32_t got, uint32_t want) {
        if (got != want)
            throw Error(strfmt("%s: unsupported %s %u (this build supports %u)", where.c_str(), field, got, want));
    };
    need("mlp_width", c.mlp_width, NB_MLP_WIDTH);
    need("mlp_hidden_layers", c.mlp_hidden_layers, NB_MLP_HIDDEN_LAYERS);
    need("mlp_outputs", c.mlp_outputs, NB_MLP_OUTPUTS);
    need("segment_points", c.segment_points, NB_SEGMENT_POINTS);
    need("grid_levels", c.grid_levels, NB_GRID_MAX_LEVELS);
    need("grid_features", c.grid_features, NB_GRID_FEATURES);
}

} // namespace

std::string Reader::str(const char* field) {
    const uint32_t n = u32();
    if (n > MODEL_MAX_STRING)
        throw Error(strfmt("%s: %s length %u exceeds %zu bytes", where_.c_str(), field, n, MODEL_MAX_STRING));
    const auto s = take(n);
    for (uint8_t c : s)
        if (c < 0x20 || c == 0x7f) throw Error(strfmt("%s: %s contains a control character", where_.c_str(), field));
    return std::string(s.begin(), s.end());
}

uint64_t header_checksum(const uint8_t* file, size_t section_count) {
    uint64_t h = fnv1a64(file, 24);
    return fnv1a64(file + HEADER_BYTES, section_count * SECTION_ENTRY_BYTES, h);
}

void validate_nodes(const std::vector<NbvhNode>& nodes, uint32_t lod_count, const std::string& name) {
    const std::string where = name + ": nodes";
    if (nodes.empty()) throw Error(where + ": no nodes");
    if (nodes.size() > NBVH_MAX_NODES) throw Error(strfmt("%s: %zu nodes is too many", where.c_str(), nodes.size()));
    std::vector<uint8_t> referenced(nodes.size(), 0);
    std::vector<uint32_t> depth(nodes.size(), 0);
    for (size_t i = 0; i < nodes.size(); ++i) {
        const NbvhNode& n = nodes[i];
        if (!finite3(n.bounds.lo) || !finite3(n.bounds.hi))
            throw Error(strfmt("%s: node %zu has non-finite bounds", where.c_str(), i));
        if (n.bounds.empty()) throw Error(strfmt("%s: node %zu has empty bounds (min > max)", where.c_str(), i));
        if (n.lod != NBVH_LOD_NONE && n.lod >= lod_count)
            throw Error(strfmt("%s: node %zu has LoD code %u but the model has %u LoDs", where.c_str(), i, n.lod, lod_count));
        if (!n.has_children()) {
            if (n.lod != 0) throw Error(strfmt("%s: leaf %zu is not a leaf of LoD 0 (code %u)", where.c_str(), i, n.lod));
            continue;
        }
        if (n.final_leaf) throw Error(strfmt("%s: node %zu is a final leaf but has children", where.c_str(), i));
        if (n.lod == 0) throw Error(strfmt("%s: node %zu is a leaf at every LoD but has children", where.c_str(), i));
        if (n.left <= i || n.left >= nodes.size() - 1)
            throw Error(strfmt("%s: node %zu has child index %u out of range", where.c_str(), i, n.left));
        for (uint32_t c = n.left; c <= n.left + 1; ++c) {
            if (referenced[c]++) throw Error(strfmt("%s: node %u has two parents", where.c_str(), c));
            depth[c] = depth[i] + 1;
            if (depth[c] >= NB_BVH_MAX_DEPTH)
                throw Error(strfmt("%s: tree deeper than %u levels", where.c_str(), NB_BVH_MAX_DEPTH));
        }
    }
    // Children always have larger indices, so every referenced node is reached from the root; the
    // count then proves it is one tree.
    for (size_t i = 1; i < nodes.size(); ++i)
        if (!referenced[i]) throw Error(strfmt("%s: node %zu is not reachable from the root", where.c_str(), i));
}

std::vector<Section> encode_sections(const NeuralModel& m) {
    std::vector<Section> out;
    std::vector<uint8_t> b;
    {
        Writer w(b);
        const NeuralConfig& c = m.cfg;
        for (uint32_t v : {c.grid_levels, c.grid_features, c.base_resolution}) w.u32(v);
        w.f32(c.per_level_scale);
        for (uint32_t v : {c.log2_hash_size, c.segment_points, c.mlp_width, c.mlp_hidden_layers, c.mlp_outputs,
                           m.lod_count})
            w.u32(v);
        out.push_back(make(ID_CONF, std::move(b)));
    }
    {
        b.clear();
        Writer w(b);
        for (int k = 0; k < 3; ++k) w.f32(m.encoding_box.lo[k]);
        for (int k = 0; k < 3; ++k) w.f32(m.encoding_box.hi[k]);
        w.u32(uint32_t(m.assets.size()));
        w.u32(0);
        for (const ModelAsset& a : m.assets) {
            w.str(a.name);
            w.str(a.mesh);
            w.str(a.material);
            w.u32(uint32_t(a.node_paths.size()));
            for (const std::string& p : a.node_paths) w.str(p);
            w.u64(a.geometry_hash);
            w.u64(a.material_hash);
            w.u32(a.root);
            w.u32(a.triangles);
            w.f32(a.scale);
            for (int k = 0; k < 3; ++k) w.f32(a.offset[k]);
        }
        out.push_back(make(ID_ASSET, std::move(b)));
    }
    {
        b.clear();
        Writer w(b);
        w.u32(uint32_t(m.levels.size()));
        w.u32(0);
        for (const GpuHashLevel& l : m.levels) {
            w.u32(l.offset); w.u32(l.size); w.u32(l.resolution); w.f32(l.scale); w.u32(l.hashed);
            w.u32(0); w.u32(0); w.u32(0);
        }
        out.push_back(make(ID_LEVELS, std::move(b)));
    }
    {
        b.clear();
        Writer w(b);
        w.u32(uint32_t(m.lod_node_counts.size()));
        for (uint32_t c : m.lod_node_counts) w.u32(c);
        out.push_back(make(ID_LODS, std::move(b)));
    }
    {
        b.clear();
        b.reserve(8 + m.nodes.size() * NODE_RECORD_BYTES);
        Writer w(b);
        w.u32(uint32_t(m.nodes.size()));
        w.u32(0);
        for (const NbvhNode& n : m.nodes) {
            for (int k = 0; k < 3; ++k) w.f32(n.bounds.lo[k]);
            for (int k = 0; k < 3; ++k) w.f32(n.bounds.hi[k]);
            w.u32(n.left);
            w.u32(n.base_node);
            w.u8(n.lod);
            w.u8(n.final_leaf ? NODE_FLAG_FINAL : 0);
            w.u16(0);
            w.u32(0);
        }
        out.push_back(make(ID_NODES, std::move(b)));
    }
    {
        b.clear();
        Writer w(b);
        w.u32(uint32_t(m.mlp.size()));
        w.u32(0);
        put_halves(w, m.mlp);
        out.push_back(make(ID_MLP, std::move(b)));
    }
    {
        b.clear();
        Writer w(b);
        w.u64(m.grid.size());
        put_halves(w, m.grid);
        out.push_back(make(ID_GRID, std::move(b)));
    }
    {
        b.clear();
        Writer w(b);
        const TrainingMetadata& t = m.meta;
        w.u64(t.steps); w.f64(t.seconds); w.f32(t.final_loss); w.u32(t.batch_size);
        w.u64(t.source_hash); w.i64(t.created_unix);
        w.u64(t.source_triangles); w.u64(t.source_vertices);
        w.u32(t.splitting_interval); w.u32(t.last_split_iteration); w.u32(t.start_split_num);
        w.f32(t.split_scaling); w.f32(t.split_interval_scaling);
        w.str(t.backend);
        w.str(t.source);
        out.push_back(make(ID_META, std::move(b)));
    }
    // Optional per-node tables: node count, words per node, the words.
    auto node_words = [&](const char id[4], const std::vector<uint32_t>& words, uint32_t per_node) {
        if (words.empty()) return;
        NBVH_CHECK(words.size() == m.nodes.size() * size_t(per_node));
        b.clear();
        Writer w(b);
        w.u32(uint32_t(m.nodes.size()));
        w.u32(per_node);
        for (uint32_t v : words) w.u32(v);
        out.push_back(make(id, std::move(b)));
    };
    node_words(ID_OCC, m.occupancy, NB_OCC_WORDS);
    if (!m.node_materials.empty()) {
        b.clear();
        Writer w(b);
        w.u32(uint32_t(m.nodes.size()));
        w.u32(0);
        for (uint32_t v : m.node_materials) w.u32(v);
        out.push_back(make(ID_MATL, std::move(b)));
    }
    node_words(ID_MFIT, m.material_fits, NB_NODE_FIT_WORDS);
    return out;
}

namespace {

// Version 2: u32 count, u32 0, then per asset: str name, str mesh, str material, u32 path count + strs,
// u64 geometry hash, u64 material hash, u32 root, u32 triangles, f32 scale, f32[3] offset.
// Version 1: one asset named by a single string (root 0, identity placement, hashes unknown).
void read_assets(Reader& r, uint32_t version, NeuralModel& m) {
    if (version == 1) {
        ModelAsset a;
        a.name = a.mesh = r.str("asset name");
        m.assets.push_back(a);
        return;
    }
    constexpr size_t MIN_ASSET_BYTES = 3 * 4 + 4 + 8 + 8 + 4 + 4 + 16;
    const uint32_t count = r.u32();
    if (r.u32() != 0) throw Error(r.where() + ": reserved field is not zero");
    if (count == 0 || count > MODEL_MAX_ASSETS || count > r.remaining() / MIN_ASSET_BYTES)
        throw Error(strfmt("%s: asset count %u out of range", r.where().c_str(), count));
    m.assets.resize(count);
    for (ModelAsset& a : m.assets) {
        a.name = r.str("asset name");
        a.mesh = r.str("asset mesh");
        a.material = r.str("asset material");
        const uint32_t paths = r.u32();
        if (paths > r.remaining() / 4) throw Error(strfmt("%s: node path count %u exceeds the section", r.where().c_str(), paths));
        for (uint32_t i = 0; i < paths; ++i) a.node_paths.push_back(r.str("node path"));
        a.geometry_hash = r.u64();
        a.material_hash = r.u64();
        a.root = r.u32();
        a.triangles = r.u32();
        a.scale = r.f32();
        for (int k = 0; k < 3; ++k) a.offset[k] = r.f32();
        if (!(a.scale > 0.0f) || !std::isfinite(a.scale) || !finite3(a.offset))
            throw Error(strfmt("%s: asset '%s' has a non-finite or non-positive placement", r.where().c_str(),
                               a.name.c_str()));
    }
}

} // namespace

void validate_assets(const NeuralModel& m, const std::string& name) {
    if (m.assets.empty() || m.assets.size() > MODEL_MAX_ASSETS)
        throw Error(strfmt("%s: asset count %zu out of range", name.c_str(), m.assets.size()));
    // Roots: valid nodes whose subtrees are disjoint (no root at or below another).
    std::vector<int32_t> owner(m.nodes.size(), -1);
    for (size_t i = 0; i < m.assets.size(); ++i) {
        const ModelAsset& a = m.assets[i];
        if (a.root >= m.nodes.size())
            throw Error(strfmt("%s: asset '%s' root %u is not a node", name.c_str(), a.name.c_str(), a.root));
        if (owner[a.root] >= 0)
            throw Error(strfmt("%s: assets '%s' and '%s' share a root", name.c_str(),
                               m.assets[size_t(owner[a.root])].name.c_str(), a.name.c_str()));
        owner[a.root] = int32_t(i);
        if (!(a.scale > 0.0f) || !std::isfinite(a.scale) || !finite3(a.offset))
            throw Error(strfmt("%s: asset '%s' has a non-finite or non-positive placement", name.c_str(), a.name.c_str()));
        for (size_t j = 0; j < i; ++j)
            if (m.assets[j].name == a.name)
                throw Error(strfmt("%s: asset name '%s' appears twice", name.c_str(), a.name.c_str()));
    }
    // Parents come before children: one pass propagates ownership downwards; meeting a second root
    // below an owned node means nested subtrees.
    for (size_t i = 1; i < m.nodes.size(); ++i) {
        const uint32_t p = m.nodes[i].parent;
        if (p == NBVH_NO_CHILD || p >= m.nodes.size() || owner[p] < 0) continue;
        if (owner[i] >= 0)
            throw Error(strfmt("%s: asset '%s' lies inside asset '%s'", name.c_str(),
                               m.assets[size_t(owner[i])].name.c_str(), m.assets[size_t(owner[p])].name.c_str()));
        owner[i] = owner[p];
    }
}

NeuralModel decode_sections(const std::vector<SectionView>& sections, const std::string& name, uint32_t version) {
    auto find = [&](const char id[4]) -> Reader {
        for (const SectionView& s : sections)
            if (std::memcmp(s.id, id, 4) == 0) return Reader(s.bytes, name + ": section '" + id_string(id) + "'");
        throw Error(name + ": section '" + id_string(id) + "' is missing");
    };
    for (const SectionView& s : sections) {
        bool known = false;
        for (const char* id : ALL_IDS) known |= std::memcmp(s.id, id, 4) == 0;
        if (!known) throw Error(name + ": unknown section '" + id_string(s.id) + "'");
    }
    NeuralModel m;
    {
        Reader r = find(ID_CONF);
        NeuralConfig& c = m.cfg;
        c.grid_levels = r.u32(); c.grid_features = r.u32(); c.base_resolution = r.u32();
        c.per_level_scale = r.f32();
        c.log2_hash_size = r.u32(); c.segment_points = r.u32(); c.mlp_width = r.u32();
        c.mlp_hidden_layers = r.u32(); c.mlp_outputs = r.u32();
        m.lod_count = r.u32();
        expect_end(r);
        check_config(c, r.where());
        if (m.lod_count == 0 || m.lod_count > NBVH_MAX_LODS)
            throw Error(strfmt("%s: LoD count %u out of range [1, %u]", r.where().c_str(), m.lod_count, NBVH_MAX_LODS));
    }
    {
        Reader r = find(ID_ASSET);
        for (int k = 0; k < 3; ++k) m.encoding_box.lo[k] = r.f32();
        for (int k = 0; k < 3; ++k) m.encoding_box.hi[k] = r.f32();
        read_assets(r, version, m);
        expect_end(r);
        if (!finite3(m.encoding_box.lo) || !finite3(m.encoding_box.hi))
            throw Error(r.where() + ": encoding box is not finite");
        const glm::vec3 e = m.encoding_box.hi - m.encoding_box.lo;
        if (!(e.x > 0.0f && e.y > 0.0f && e.z > 0.0f) || !finite3(e))
            throw Error(r.where() + ": encoding box has no volume");
    }
    {
        Reader r = find(ID_LEVELS);
        const uint32_t count = r.u32();
        if (r.u32() != 0) throw Error(r.where() + ": reserved field is not zero");
        if (count != m.cfg.grid_levels)
            throw Error(strfmt("%s: %u levels but the config has %u", r.where().c_str(), count, m.cfg.grid_levels));
        for (uint32_t i = 0; i < count; ++i) {
            GpuHashLevel l{};
            l.offset = r.u32(); l.size = r.u32(); l.resolution = r.u32(); l.scale = r.f32(); l.hashed = r.u32();
            l.pad0 = r.u32(); l.pad1 = r.u32(); l.pad2 = r.u32();
            m.levels.push_back(l);
        }
        expect_end(r);
        try {
            neural::validate_level_table(m.levels);
            // Recomputed for validation only: the renderer uses the stored table.
            const std::vector<GpuHashLevel> want = neural::make_level_table(m.cfg);
            for (uint32_t i = 0; i < count; ++i) {
                const GpuHashLevel &a = m.levels[i], &b = want[i];
                if (a.offset != b.offset || a.size != b.size || a.resolution != b.resolution ||
                    std::memcmp(&a.scale, &b.scale, 4) != 0 || a.hashed != b.hashed)
                    throw Error(strfmt("level %u does not match the hyperparameters", i));
            }
        } catch (const Error& e) {
            throw Error(r.where() + ": " + e.what());
        }
    }
    {
        Reader r = find(ID_LODS);
        const uint32_t count = r.u32();
        if (count != m.lod_count)
            throw Error(strfmt("%s: %u node counts for %u LoDs", r.where().c_str(), count, m.lod_count));
        for (uint32_t i = 0; i < count; ++i) m.lod_node_counts.push_back(r.u32());
        expect_end(r);
    }
    {
        Reader r = find(ID_NODES);
        const uint32_t count = r.u32();
        if (r.u32() != 0) throw Error(r.where() + ": reserved field is not zero");
        if (count > r.remaining() / NODE_RECORD_BYTES)
            throw Error(strfmt("%s: node count %u exceeds the section size", r.where().c_str(), count));
        m.nodes.resize(count);
        for (uint32_t i = 0; i < count; ++i) {
            NbvhNode& n = m.nodes[i];
            for (int k = 0; k < 3; ++k) n.bounds.lo[k] = r.f32();
            for (int k = 0; k < 3; ++k) n.bounds.hi[k] = r.f32();
            n.left = r.u32();
            n.base_node = r.u32();
            n.lod = r.u8();
            const uint8_t flags = r.u8();
            if ((flags & ~NODE_FLAG_FINAL) != 0 || r.u16() != 0 || r.u32() != 0)
                throw Error(strfmt("%s: node %u has unknown flags or non-zero padding", r.where().c_str(), i));
            n.final_leaf = (flags & NODE_FLAG_FINAL) != 0;
        }
        expect_end(r);
        validate_nodes(m.nodes, m.lod_count, name);
        const NbvhTree tree = m.tree();
        for (uint32_t l = 0; l < m.lod_count; ++l)
            if (tree.node_count_at(l) != m.lod_node_counts[l])
                throw Error(strfmt("%s: section 'LODS': LoD %u has %u nodes, the table says %u", name.c_str(), l,
                                   tree.node_count_at(l), m.lod_node_counts[l]));
        m.nodes = tree.nodes(); // with parent and depth derived
    }
    {
        Reader r = find(ID_MLP);
        const uint32_t count = r.u32();
        if (r.u32() != 0) throw Error(r.where() + ": reserved field is not zero");
        if (count != NB_MLP_WEIGHT_COUNT)
            throw Error(strfmt("%s: %u weights, expected %u", r.where().c_str(), count, NB_MLP_WEIGHT_COUNT));
        m.mlp = get_halves(r, count, "weight");
        expect_end(r);
    }
    {
        Reader r = find(ID_GRID);
        const uint64_t count = r.u64();
        const uint64_t want = neural::level_table_entries(m.levels) * m.cfg.grid_features;
        if (count != want)
            throw Error(strfmt("%s: %llu values, the level table needs %llu", r.where().c_str(),
                               (unsigned long long)count, (unsigned long long)want));
        m.grid = get_halves(r, count, "grid");
        expect_end(r);
    }
    {
        Reader r = find(ID_META);
        TrainingMetadata& t = m.meta;
        t.steps = r.u64(); t.seconds = r.f64(); t.final_loss = r.f32(); t.batch_size = r.u32();
        t.source_hash = r.u64(); t.created_unix = r.i64();
        t.source_triangles = r.u64(); t.source_vertices = r.u64();
        t.splitting_interval = r.u32(); t.last_split_iteration = r.u32(); t.start_split_num = r.u32();
        t.split_scaling = r.f32(); t.split_interval_scaling = r.f32();
        t.backend = r.str("backend");
        t.source = r.str("source");
        expect_end(r);
        if (!std::isfinite(t.seconds) || t.seconds < 0.0 || !std::isfinite(t.final_loss) ||
            !std::isfinite(t.split_scaling) || !std::isfinite(t.split_interval_scaling))
            throw Error(r.where() + ": training metadata holds a non-finite or negative number");
    }
    // Optional per-node tables (node count, words per node, the words); `valid` checks each word.
    auto node_words = [&](const char id[4], uint32_t since, const char* what, uint32_t per_node,
                          std::vector<uint32_t>& out, bool (*valid)(uint32_t)) {
        for (const SectionView& s : sections) {
            if (std::memcmp(s.id, id, 4) != 0) continue;
            Reader r(s.bytes, name + ": section '" + id_string(id) + "'");
            if (version < since) throw Error(strfmt("%s: %s need format version %u", r.where().c_str(), what, since));
            const uint32_t count = r.u32(), words = r.u32();
            if (count != m.nodes.size() || words != per_node)
                throw Error(strfmt("%s: %u nodes x %u words, the model has %zu nodes x %u", r.where().c_str(), count,
                                   words, m.nodes.size(), per_node));
            if (r.remaining() != size_t(count) * words * 4)
                throw Error(r.where() + ": size does not match its node count");
            out.resize(size_t(count) * words);
            for (size_t k = 0; k < out.size(); ++k)
                if (!valid(out[k] = r.u32()))
                    throw Error(strfmt("%s: word %zu is not valid", r.where().c_str(), k));
            expect_end(r);
        }
    };
    node_words(ID_OCC, 3, "occupancy masks", NB_OCC_WORDS, m.occupancy, [](uint32_t) { return true; });
    // Fits: two finite fp16 per word.
    node_words(ID_MFIT, 5, "material fits", NB_NODE_FIT_WORDS, m.material_fits,
               [](uint32_t v) { return half_finite(uint16_t(v)) && half_finite(uint16_t(v >> 16)); });
    for (const SectionView& s : sections) {
        if (std::memcmp(s.id, ID_MATL, 4) != 0) continue;
        Reader r(s.bytes, name + ": section 'MATL'");
        if (version < 4) throw Error(r.where() + ": node materials need format version 4");
        const uint32_t count = r.u32();
        if (r.u32() != 0) throw Error(r.where() + ": reserved field is not zero");
        if (count != m.nodes.size())
            throw Error(strfmt("%s: %u nodes, the model has %zu", r.where().c_str(), count, m.nodes.size()));
        if (r.remaining() != size_t(count) * 4) throw Error(r.where() + ": size does not match its node count");
        m.node_materials.resize(count);
        for (uint32_t& v : m.node_materials) v = r.u32(); // every word is a valid unorm16 pair
        expect_end(r);
    }
    validate_assets(m, name);
    m.file_version = version;
    return m;
}

} // namespace nbvh::model_io
