#include "engine/scene/gltf_accessor.h"

#include <algorithm>
#include <cstring>

#include <tiny_gltf.h>

#include "engine/core/error.h"
#include "engine/core/log.h"

namespace nbvh::gltf {

int component_count(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
    }
}

int component_size(int component_type) {
    switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0; // INT and DOUBLE are not valid glTF 2.0 vertex/index component types
    }
}

namespace {

// A validated window into a buffer: `count` elements of `elem_size` bytes, `stride` apart.
struct Span {
    const uint8_t* data = nullptr;
    uint64_t count = 0;
    uint32_t stride = 0;
};

// Checks bufferView `view_index` and that `count` elements of `elem_size` at `offset` (optionally with the
// view's byteStride) fit inside it and inside the loaded buffer data. Throws nbvh::Error naming the problem.
Span checked_span(const tinygltf::Model& model, int view_index, uint64_t offset, uint64_t count, uint32_t elem_size,
                  bool allow_stride, const std::string& what) {
    if (view_index < 0 || size_t(view_index) >= model.bufferViews.size())
        throw Error(strfmt("%s: bufferView %d does not exist (%zu bufferViews)", what.c_str(), view_index,
                           model.bufferViews.size()));
    const tinygltf::BufferView& view = model.bufferViews[size_t(view_index)];
    if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size())
        throw Error(strfmt("%s: bufferView %d refers to buffer %d which does not exist", what.c_str(), view_index,
                           view.buffer));
    const tinygltf::Buffer& buffer = model.buffers[size_t(view.buffer)];
    const uint64_t view_offset = view.byteOffset, view_length = view.byteLength;
    if (view_offset > buffer.data.size() || view_length > buffer.data.size() - view_offset)
        throw Error(strfmt("%s: bufferView %d (offset %llu, length %llu) exceeds buffer %d ('%s', %zu bytes loaded)",
                           what.c_str(), view_index, (unsigned long long)view_offset,
                           (unsigned long long)view_length, view.buffer, buffer.uri.c_str(), buffer.data.size()));
    uint32_t stride = elem_size;
    if (allow_stride && view.byteStride != 0) {
        if (view.byteStride < elem_size || view.byteStride > 252)
            throw Error(strfmt("%s: bufferView %d byteStride %zu is invalid for %u-byte elements", what.c_str(),
                               view_index, view.byteStride, elem_size));
        stride = uint32_t(view.byteStride);
    }
    Span span;
    span.stride = stride;
    span.count = count;
    if (count == 0) return span;
    // (count-1)*stride + elem_size <= length - offset, checked by division so a hostile count cannot overflow.
    if (offset > view_length || view_length - offset < elem_size ||
        count - 1 > (view_length - offset - elem_size) / stride)
        throw Error(strfmt("%s: accessor count %llu (%u-byte elements, stride %u, offset %llu) does not fit in "
                           "bufferView %d of %llu bytes",
                           what.c_str(), (unsigned long long)count, elem_size, stride, (unsigned long long)offset,
                           view_index, (unsigned long long)view_length));
    span.data = buffer.data.data() + view_offset + offset;
    return span;
}

double decode(const uint8_t* p, int ctype, bool normalized) {
    switch (ctype) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float f;
        std::memcpy(&f, p, 4);
        return f;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? p[0] / 255.0 : p[0];
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
        const int8_t v = int8_t(p[0]);
        return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t v;
        std::memcpy(&v, p, 4);
        return normalized ? v / 4294967295.0 : v;
    }
    default: return 0.0;
    }
}

uint32_t decode_index(const uint8_t* p, int ctype) {
    switch (ctype) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return p[0];
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p, 2);
        return v;
    }
    default: {
        uint32_t v;
        std::memcpy(&v, p, 4);
        return v;
    }
    }
}

// An accessor without a bufferView is zeros plus sparse substitutions: no file data backs its count, so it gets
// a far smaller limit than MAX_ACCESSOR_COUNT (2^28 zero positions took 13 GB and a minute; fuzz regression
// seed crash_zero_accessor_huge_count.gltf).
constexpr uint64_t MAX_ZERO_ACCESSOR_COUNT = uint64_t(1) << 20;

const tinygltf::Accessor& checked_accessor(const tinygltf::Model& model, int index, const std::string& what) {
    if (index < 0 || size_t(index) >= model.accessors.size())
        throw Error(strfmt("%s: accessor %d does not exist (%zu accessors)", what.c_str(), index,
                           model.accessors.size()));
    const tinygltf::Accessor& a = model.accessors[size_t(index)];
    if (a.count > MAX_ZERO_ACCESSOR_COUNT && a.bufferView < 0)
        throw Error(strfmt("%s: accessor %d has no bufferView and count %zu exceeds the limit of %llu zero-filled "
                           "elements", what.c_str(), index, a.count, (unsigned long long)MAX_ZERO_ACCESSOR_COUNT));
    return a;
}

// Reads the raw elements of accessor `a` (base data + sparse substitution) through `store(i, element_ptr, ctype)`.
template <class Store>
void visit_elements(const tinygltf::Model& model, const tinygltf::Accessor& a, uint32_t elem_size,
                    const std::string& what, Store&& store) {
    if (a.bufferView >= 0) {
        const Span span = checked_span(model, a.bufferView, a.byteOffset, a.count, elem_size, true, what);
        if (a.count > MAX_ACCESSOR_COUNT)
            throw Error(strfmt("%s: accessor count %zu exceeds the limit of %llu elements", what.c_str(), a.count,
                               (unsigned long long)MAX_ACCESSOR_COUNT));
        for (uint64_t i = 0; i < span.count; ++i) store(i, span.data + i * span.stride, a.componentType);
    } // else: all zeros (glTF 2.0 §3.6.2.3), the caller's vector is zero-initialised
    if (!a.sparse.isSparse) return;
    const int sparse_count = a.sparse.count;
    if (sparse_count < 1 || uint64_t(sparse_count) > a.count)
        throw Error(strfmt("%s: sparse count %d is invalid for an accessor of %zu elements", what.c_str(),
                           sparse_count, a.count));
    const int ictype = a.sparse.indices.componentType;
    if (ictype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ictype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        ictype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
        throw Error(strfmt("%s: sparse indices componentType %d is invalid", what.c_str(), ictype));
    if (a.sparse.indices.byteOffset < 0 || a.sparse.values.byteOffset < 0)
        throw Error(strfmt("%s: negative sparse byteOffset", what.c_str()));
    const Span idx = checked_span(model, a.sparse.indices.bufferView, uint64_t(a.sparse.indices.byteOffset),
                                  uint64_t(sparse_count), uint32_t(component_size(ictype)), false, what + " sparse indices");
    const Span val = checked_span(model, a.sparse.values.bufferView, uint64_t(a.sparse.values.byteOffset),
                                  uint64_t(sparse_count), elem_size, false, what + " sparse values");
    for (uint64_t k = 0; k < uint64_t(sparse_count); ++k) {
        const uint32_t target = decode_index(idx.data + k * idx.stride, ictype);
        if (target >= a.count)
            throw Error(strfmt("%s: sparse index %u out of range (%zu elements)", what.c_str(), target, a.count));
        store(target, val.data + k * val.stride, a.componentType);
    }
}

} // namespace

uint64_t accessor_count(const tinygltf::Model& model, int index, const std::string& what) {
    return checked_accessor(model, index, what).count;
}

std::vector<float> read_floats(const tinygltf::Model& model, int index, int components, const std::string& what) {
    const tinygltf::Accessor& a = checked_accessor(model, index, what);
    const int n = component_count(a.type);
    if (n != components)
        throw Error(strfmt("%s: accessor %d has %d components per element, expected %d", what.c_str(), index, n,
                           components));
    const int csize = component_size(a.componentType);
    if (csize == 0 || (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT && a.normalized))
        throw Error(strfmt("%s: accessor %d has invalid componentType %d", what.c_str(), index, a.componentType));
    const uint32_t elem_size = uint32_t(csize * n);
    // Validate the whole layout first (throws), only then allocate.
    if (a.bufferView >= 0) checked_span(model, a.bufferView, a.byteOffset, a.count, elem_size, true, what);
    if (a.count > MAX_ACCESSOR_COUNT)
        throw Error(strfmt("%s: accessor count %zu exceeds the limit of %llu elements", what.c_str(), a.count,
                           (unsigned long long)MAX_ACCESSOR_COUNT));
    std::vector<float> out(size_t(a.count) * size_t(n), 0.0f);
    const bool normalized = a.normalized;
    visit_elements(model, a, elem_size, what, [&](uint64_t i, const uint8_t* p, int ctype) {
        for (int c = 0; c < n; ++c) out[size_t(i) * n + c] = float(decode(p + c * csize, ctype, normalized));
    });
    return out;
}

std::vector<uint32_t> read_indices(const tinygltf::Model& model, int index, const std::string& what) {
    const tinygltf::Accessor& a = checked_accessor(model, index, what);
    if (a.type != TINYGLTF_TYPE_SCALAR)
        throw Error(strfmt("%s: index accessor %d is not SCALAR", what.c_str(), index));
    if (a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
        throw Error(strfmt("%s: index accessor %d has invalid componentType %d (must be an unsigned integer type)",
                           what.c_str(), index, a.componentType));
    const uint32_t elem_size = uint32_t(component_size(a.componentType));
    if (a.bufferView >= 0) checked_span(model, a.bufferView, a.byteOffset, a.count, elem_size, true, what);
    if (a.count > MAX_ACCESSOR_COUNT)
        throw Error(strfmt("%s: accessor count %zu exceeds the limit of %llu elements", what.c_str(), a.count,
                           (unsigned long long)MAX_ACCESSOR_COUNT));
    std::vector<uint32_t> out(size_t(a.count), 0u);
    visit_elements(model, a, elem_size, what,
                   [&](uint64_t i, const uint8_t* p, int ctype) { out[size_t(i)] = decode_index(p, ctype); });
    return out;
}

} // namespace nbvh::gltf
