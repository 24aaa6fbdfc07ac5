// Internals of the .nbvh format (model_file.cpp): byte readers/writers with bounds checks and the
// encoding/decoding of each section. Not for use outside engine/neural and its tests.
#pragma once
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "engine/core/error.h"
#include "engine/neural/model_file.h"

namespace nbvh::model_io {

inline constexpr char MAGIC[4] = {'N', 'B', 'V', 'H'};
inline constexpr size_t HEADER_BYTES = 32;
inline constexpr size_t SECTION_ENTRY_BYTES = 32;
inline constexpr uint32_t MAX_SECTIONS = 64;
inline constexpr size_t NODE_RECORD_BYTES = 40;

// Appends (or overwrites from `pos` on) little-endian values.
class Writer {
public:
    Writer(std::vector<uint8_t>& out, size_t pos) : out_(out), pos_(pos) {}
    explicit Writer(std::vector<uint8_t>& out) : out_(out), pos_(out.size()) {}
    void bytes(const void* p, size_t n) {
        if (pos_ + n > out_.size()) out_.resize(pos_ + n);
        std::memcpy(out_.data() + pos_, p, n);
        pos_ += n;
    }
    void u8(uint8_t v) { bytes(&v, 1); }
    void u16(uint16_t v) { bytes(&v, 2); }
    void u32(uint32_t v) { bytes(&v, 4); }
    void u64(uint64_t v) { bytes(&v, 8); }
    void i64(int64_t v) { bytes(&v, 8); }
    void f32(float v) { bytes(&v, 4); }
    void f64(double v) { bytes(&v, 8); }
    void str(const std::string& s) { u32(uint32_t(s.size())); bytes(s.data(), s.size()); }

private:
    std::vector<uint8_t>& out_;
    size_t pos_;
};

// Reads from a span; running past its end throws "<where>: truncated".
class Reader {
public:
    Reader(std::span<const uint8_t> bytes, std::string where) : b_(bytes), where_(std::move(where)) {}
    std::span<const uint8_t> take(size_t n) {
        if (n > b_.size() - pos_) throw Error(where_ + ": truncated (section shorter than its contents)");
        auto s = b_.subspan(pos_, n);
        pos_ += n;
        return s;
    }
    void skip(size_t n) { take(n); }
    template <class T> T pod() { T v; std::memcpy(&v, take(sizeof(T)).data(), sizeof(T)); return v; }
    uint8_t u8() { return pod<uint8_t>(); }
    uint16_t u16() { return pod<uint16_t>(); }
    uint32_t u32() { return pod<uint32_t>(); }
    uint64_t u64() { return pod<uint64_t>(); }
    int64_t i64() { return pod<int64_t>(); }
    float f32() { return pod<float>(); }
    double f64() { return pod<double>(); }
    std::string str(const char* field); // bounded, printable
    size_t remaining() const { return b_.size() - pos_; }
    const std::string& where() const { return where_; }

private:
    std::span<const uint8_t> b_;
    size_t pos_ = 0;
    std::string where_;
};

struct Section {
    char id[4];
    std::vector<uint8_t> payload;
};
struct SectionView {
    char id[4];
    std::span<const uint8_t> bytes;
};

inline std::string id_string(const char id[4]) {
    std::string s;
    for (int i = 0; i < 4; ++i) s += (id[i] >= 0x20 && id[i] < 0x7f) ? id[i] : '?';
    return s;
}

// fnv1a64 over header bytes [0, 24) and the section table.
uint64_t header_checksum(const uint8_t* file, size_t section_count);

std::vector<Section> encode_sections(const NeuralModel& model);
NeuralModel decode_sections(const std::vector<SectionView>& sections, const std::string& name, uint32_t version);
// The asset table against the nodes (parents derived): roots valid and subtrees disjoint, names unique.
void validate_assets(const NeuralModel& model, const std::string& name);

// Structure of an untrusted node array (children after parents, adjacent, each node referenced once,
// LoD codes in range, finite bounds, depth within the GPU stack). Throws nbvh::Error.
void validate_nodes(const std::vector<NbvhNode>& nodes, uint32_t lod_count, const std::string& name);

} // namespace nbvh::model_io
