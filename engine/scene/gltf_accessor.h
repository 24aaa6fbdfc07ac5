// Bounds-checked reading of glTF accessors (internal to the glTF loader).
// Every size is validated against the bufferView and the buffer BEFORE anything is allocated, so a hostile
// `count` (bad/generated/huge_count.gltf: 2e9 over 48 bytes) is a clear nbvh::Error, never a 24 GB vector.
// Sparse accessors are supported (base data or zeros, then the sparse substitution, all checked).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace tinygltf {
class Model;
}

namespace nbvh::gltf {

// Upper bound on elements of one accessor (a sanity limit well above any real asset, below 2^32 indices).
constexpr uint64_t MAX_ACCESSOR_COUNT = uint64_t(1) << 28;

// Number of components of a TINYGLTF_TYPE_* (1 for SCALAR ... 16 for MAT4), 0 when unknown.
int component_count(int type);
// Bytes of one TINYGLTF_COMPONENT_TYPE_*, 0 when unknown.
int component_size(int component_type);

// Reads accessor `index` as floats, `components` per element (the accessor's type must have exactly that many).
// Integer component types are converted as glTF says: normalized -> [0,1] / [-1,1], otherwise by value.
// `what` names the use in error messages ("mesh 'x' primitive 0 POSITION").
std::vector<float> read_floats(const tinygltf::Model& model, int index, int components, const std::string& what);

// Reads a SCALAR accessor of UNSIGNED_BYTE/SHORT/INT as indices (any other type is an error).
std::vector<uint32_t> read_indices(const tinygltf::Model& model, int index, const std::string& what);

// The element count of accessor `index` after validating the index itself (no data is read).
uint64_t accessor_count(const tinygltf::Model& model, int index, const std::string& what);

} // namespace nbvh::gltf
