// .nbvh writer and validating reader. Format (version 1), all little-endian; table in README.md:
//   header (32 bytes): "NBVH", u32 version, u32 section count, u32 0, u64 file size,
//                      u64 fnv1a64(header bytes 0..23 + section table)
//   section table: per section {char id[4], u32 0, u64 offset, u64 size, u64 fnv1a64(payload)}
//   sections at 8-aligned offsets, zero padding between them.
#include "engine/neural/model_file.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <unistd.h>

#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/neural/model_sections.h"

static_assert(std::endian::native == std::endian::little, "the model file code assumes a little-endian host");

namespace nbvh {

uint64_t fnv1a64(const void* data, size_t size, uint64_t hash) {
    const uint8_t* p = static_cast<const uint8_t*>(data);
    for (size_t i = 0; i < size; ++i) {
        hash ^= p[i];
        hash *= 0x100000001b3ull;
    }
    return hash;
}

std::vector<uint8_t> read_model_file_bytes(const std::filesystem::path& path, uint64_t max_bytes) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) throw Error(strfmt("%s: is a directory", path.c_str()));
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) throw Error(strfmt("%s: cannot open file", path.c_str()));
    const std::streamoff size = in.tellg();
    if (size < 0) throw Error(strfmt("%s: cannot read file size", path.c_str()));
    if (uint64_t(size) > max_bytes)
        throw Error(strfmt("%s: file of %lld bytes is larger than the %llu-byte limit", path.c_str(),
                           (long long)size, (unsigned long long)max_bytes));
    std::vector<uint8_t> bytes(static_cast<size_t>(size));
    in.seekg(0);
    if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), size))
        throw Error(strfmt("%s: read error", path.c_str()));
    return bytes;
}

uint64_t fnv1a64_file(const std::filesystem::path& path) {
    const std::vector<uint8_t> bytes = read_model_file_bytes(path, uint64_t(1) << 40);
    return fnv1a64(bytes.data(), bytes.size());
}

void set_tree(NeuralModel& model, const NbvhTree& tree) {
    NBVH_CHECK_MSG(tree.frozen(), "set_tree needs a finished tree (call finish_lods)");
    model.nodes = tree.nodes();
    model.lod_count = tree.lod_count();
    model.lod_node_counts.clear();
    for (uint32_t l = 0; l < tree.lod_count(); ++l) model.lod_node_counts.push_back(tree.node_count_at(l));
}

// ---- writing ----

std::vector<uint8_t> serialize_model(const NeuralModel& model) {
    std::vector<model_io::Section> sections = model_io::encode_sections(model);
    const size_t table_bytes = sections.size() * model_io::SECTION_ENTRY_BYTES;
    std::vector<uint8_t> out(model_io::HEADER_BYTES + table_bytes, 0);
    std::vector<uint64_t> offsets;
    for (const model_io::Section& s : sections) {
        out.resize((out.size() + 7) & ~size_t(7), 0);
        offsets.push_back(out.size());
        out.insert(out.end(), s.payload.begin(), s.payload.end());
    }
    out.resize((out.size() + 7) & ~size_t(7), 0);
    model_io::Writer h(out, 0);
    h.bytes(model_io::MAGIC, 4);
    h.u32(MODEL_FORMAT_VERSION);
    h.u32(uint32_t(sections.size()));
    h.u32(0);
    h.u64(out.size());
    h.u64(0); // header checksum, below
    for (size_t i = 0; i < sections.size(); ++i) {
        h.bytes(sections[i].id, 4);
        h.u32(0);
        h.u64(offsets[i]);
        h.u64(sections[i].payload.size());
        h.u64(fnv1a64(sections[i].payload.data(), sections[i].payload.size()));
    }
    const uint64_t header_hash = model_io::header_checksum(out.data(), sections.size());
    std::memcpy(out.data() + 24, &header_hash, 8);
    // Never write what the reader would reject.
    (void)parse_model(out, "model being saved");
    return out;
}

void save_model(const std::filesystem::path& path, const NeuralModel& model) {
    const std::vector<uint8_t> bytes = serialize_model(model);
    std::filesystem::path tmp = path;
    tmp += strfmt(".tmp%ld", long(::getpid()));
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) throw Error(strfmt("%s: cannot create file", tmp.c_str()));
        out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
        out.flush();
        if (!out) {
            out.close();
            std::error_code ec;
            std::filesystem::remove(tmp, ec);
            throw Error(strfmt("%s: write error (disk full?)", tmp.c_str()));
        }
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
        std::filesystem::remove(tmp, ec);
        throw Error(strfmt("%s: cannot replace file: %s", path.c_str(), ec.message().c_str()));
    }
}

// ---- reading ----

NeuralModel parse_model(std::span<const uint8_t> bytes, const std::string& name) {
    auto fail = [&](const std::string& what) -> Error { return Error(name + ": " + what); };
    if (bytes.size() < 4 || std::memcmp(bytes.data(), model_io::MAGIC, 4) != 0) {
        if (looks_like_official_tree(bytes))
            throw fail("not an nbvh model (official N-BVH tree file? it holds only the tree, no network)");
        throw fail(bytes.size() < 4 ? "not an nbvh model (file too short)" : "not an nbvh model (bad magic)");
    }
    if (bytes.size() < model_io::HEADER_BYTES) throw fail("truncated: header incomplete");
    model_io::Reader h(bytes.subspan(0, model_io::HEADER_BYTES), name + ": header");
    h.skip(4);
    const uint32_t version = h.u32();
    if (version == 0 || version > MODEL_FORMAT_VERSION)
        throw fail(strfmt("unsupported model format version %u (this build reads versions 1 to %u)", version,
                          MODEL_FORMAT_VERSION));
    const uint32_t section_count = h.u32();
    if (h.u32() != 0) throw fail("header: reserved field is not zero");
    const uint64_t file_size = h.u64();
    const uint64_t header_hash = h.u64();
    if (file_size != bytes.size())
        throw fail(strfmt("%s: header says %llu bytes, file has %zu", file_size > bytes.size() ? "truncated" : "trailing data",
                          (unsigned long long)file_size, bytes.size()));
    if (section_count == 0 || section_count > model_io::MAX_SECTIONS)
        throw fail(strfmt("header: section count %u out of range", section_count));
    const size_t table_end = model_io::HEADER_BYTES + size_t(section_count) * model_io::SECTION_ENTRY_BYTES;
    if (table_end > bytes.size()) throw fail("truncated: section table incomplete");
    if (model_io::header_checksum(bytes.data(), section_count) != header_hash)
        throw fail("header checksum mismatch (corrupted file)");

    std::vector<model_io::SectionView> views;
    model_io::Reader t(bytes.subspan(model_io::HEADER_BYTES, table_end - model_io::HEADER_BYTES),
                       name + ": section table");
    for (uint32_t i = 0; i < section_count; ++i) {
        model_io::SectionView v;
        std::memcpy(v.id, t.take(4).data(), 4);
        const std::string id = model_io::id_string(v.id);
        if (t.u32() != 0) throw fail("section '" + id + "': reserved field is not zero");
        const uint64_t offset = t.u64(), size = t.u64(), hash = t.u64();
        if (offset % 8 != 0 || offset < table_end || offset > bytes.size() || size > bytes.size() - offset)
            throw fail(strfmt("section '%s': offset %llu / size %llu outside the file (%zu bytes)", id.c_str(),
                              (unsigned long long)offset, (unsigned long long)size, bytes.size()));
        v.bytes = bytes.subspan(size_t(offset), size_t(size));
        if (fnv1a64(v.bytes.data(), v.bytes.size()) != hash)
            throw fail("section '" + id + "': checksum mismatch (corrupted file)");
        for (const model_io::SectionView& o : views)
            if (std::memcmp(o.id, v.id, 4) == 0) throw fail("section '" + id + "' appears twice");
        views.push_back(v);
    }
    // Sections must not overlap (each byte has one meaning).
    std::vector<model_io::SectionView> sorted = views;
    std::sort(sorted.begin(), sorted.end(),
              [](const auto& a, const auto& b) { return a.bytes.data() < b.bytes.data(); });
    for (size_t i = 1; i < sorted.size(); ++i)
        if (sorted[i].bytes.data() < sorted[i - 1].bytes.data() + sorted[i - 1].bytes.size())
            throw fail("sections '" + model_io::id_string(sorted[i - 1].id) + "' and '" +
                       model_io::id_string(sorted[i].id) + "' overlap");
    return model_io::decode_sections(views, name, version);
}

NeuralModel load_model(const std::filesystem::path& path) {
    // 16 GiB: far above any model (a 2^24-entry hash grid is 1 GiB) yet refuses absurd inputs.
    const std::vector<uint8_t> bytes = read_model_file_bytes(path, uint64_t(16) << 30);
    return parse_model(bytes, path.string());
}

uint64_t model_gpu_bytes(const NeuralModel& m) {
    const uint64_t interior = m.lod_node_counts.empty() ? 1 : (uint64_t(m.lod_node_counts[0]) / 2 + 1);
    return interior * sizeof(GpuBvhNode) + m.mlp.size() * 2 + m.grid.size() * 2 +
           m.levels.size() * sizeof(GpuHashLevel) + m.occupancy.size() * 4 + m.node_materials.size() * 4 +
           m.material_fits.size() * 4;
}

// ---- the official tree file (notes §10) ----

bool looks_like_official_tree(std::span<const uint8_t> bytes) {
    if (bytes.size() < 24) return false;
    uint64_t n, prims;
    std::memcpy(&n, bytes.data(), 8);
    std::memcpy(&prims, bytes.data() + 8, 8);
    return n >= 1 && n <= (bytes.size() - 24) / 40 && 16 + 40 * n + 8 * prims == bytes.size();
}

std::vector<NbvhNode> import_official_tree(std::span<const uint8_t> bytes, const std::string& name) {
    auto fail = [&](const std::string& what) -> Error { return Error(name + ": " + what); };
    if (!looks_like_official_tree(bytes)) throw fail("not an official N-BVH tree file (sizes do not match)");
    uint64_t n;
    std::memcpy(&n, bytes.data(), 8);
    if (n > NBVH_MAX_NODES) throw fail(strfmt("%llu nodes is too many", (unsigned long long)n));
    model_io::Reader r(bytes.subspan(16, size_t(40 * n)), name);
    std::vector<NbvhNode> nodes(static_cast<size_t>(n));
    for (uint64_t i = 0; i < n; ++i) {
        NbvhNode& node = nodes[size_t(i)];
        float b[6];
        for (float& f : b) f = r.f32();
        node.bounds.lo = glm::vec3(b[0], b[2], b[4]); // interleaved min.x, max.x, min.y, ...
        node.bounds.hi = glm::vec3(b[1], b[3], b[5]);
        const uint64_t first = r.u64(), code = r.u64();
        node.left = first == 0xFFFFFFFFull ? NBVH_NO_CHILD : uint32_t(std::min<uint64_t>(first, 0xFFFFFFFEull));
        if (code > 8) throw fail(strfmt("node %llu: unknown leaf code %llu", (unsigned long long)i, (unsigned long long)code));
        node.final_leaf = code == 1;
        node.lod = node.left == NBVH_NO_CHILD ? 0 : NBVH_LOD_NONE;
    }
    model_io::validate_nodes(nodes, 1, name);
    return nodes;
}

std::vector<NbvhNode> import_official_tree(const std::filesystem::path& path) {
    const std::vector<uint8_t> bytes = read_model_file_bytes(path, uint64_t(16) << 30);
    return import_official_tree(bytes, path.string());
}

} // namespace nbvh
