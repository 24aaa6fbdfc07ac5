// Small glTF documents built in memory for loader tests (embedded base64 buffers), written to a temporary
// file by write_gltf.
#pragma once
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace nbvh::test {

inline std::string base64_of(const std::vector<uint8_t>& in) {
    static const char* abc = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < in.size(); i += 3) {
        const uint32_t n = (uint32_t(in[i]) << 16) | (i + 1 < in.size() ? uint32_t(in[i + 1]) << 8 : 0u) |
                           (i + 2 < in.size() ? uint32_t(in[i + 2]) : 0u);
        out += abc[(n >> 18) & 63];
        out += abc[(n >> 12) & 63];
        out += i + 1 < in.size() ? abc[(n >> 6) & 63] : '=';
        out += i + 2 < in.size() ? abc[n & 63] : '=';
    }
    return out;
}

// Builds one buffer from typed arrays; each add() returns the index of a new bufferView + accessor.
class GltfBuilder {
public:
    nlohmann::json doc = {{"asset", {{"version", "2.0"}}}};

    template <class T>
    int add(const std::vector<T>& values, int component_type, const char* type, bool normalized = false,
            int target = 0) {
        while (bytes_.size() % 4) bytes_.push_back(0);
        const size_t offset = bytes_.size();
        bytes_.resize(offset + values.size() * sizeof(T));
        std::memcpy(bytes_.data() + offset, values.data(), values.size() * sizeof(T));
        nlohmann::json view = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", values.size() * sizeof(T)}};
        if (target) view["target"] = target;
        doc["bufferViews"].push_back(view);
        const size_t comps = std::string(type) == "SCALAR" ? 1 : std::string(type) == "VEC2" ? 2
                           : std::string(type) == "VEC3"   ? 3 : std::string(type) == "VEC4" ? 4 : 16;
        nlohmann::json acc = {{"bufferView", doc["bufferViews"].size() - 1}, {"componentType", component_type},
                              {"count", values.size() / comps}, {"type", type}};
        if (normalized) acc["normalized"] = true;
        doc["accessors"].push_back(acc);
        return int(doc["accessors"].size() - 1);
    }
    // Float VEC3 positions with the min/max glTF requires.
    int add_positions(const std::vector<float>& xyz) {
        const int a = add(xyz, 5126, "VEC3");
        std::vector<float> lo(3, 3.4e38f), hi(3, -3.4e38f);
        for (size_t i = 0; i < xyz.size(); ++i) {
            lo[i % 3] = std::min(lo[i % 3], xyz[i]);
            hi[i % 3] = std::max(hi[i % 3], xyz[i]);
        }
        doc["accessors"][size_t(a)]["min"] = lo;
        doc["accessors"][size_t(a)]["max"] = hi;
        return a;
    }
    // The document with its buffer embedded.
    nlohmann::json finish() const {
        nlohmann::json d = doc;
        d["buffers"] = nlohmann::json::array(
            {{{"byteLength", bytes_.size()}, {"uri", "data:application/octet-stream;base64," + base64_of(bytes_)}}});
        return d;
    }

private:
    std::vector<uint8_t> bytes_;
};

// A unit quad in z = 0 (two triangles, mesh 0 on node 0 of scene 0).
inline GltfBuilder quad_gltf() {
    GltfBuilder b;
    const int pos = b.add_positions({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});
    const int idx = b.add(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}, 5123, "SCALAR");
    b.doc["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", pos}}}, {"indices", idx}}}}}};
    b.doc["nodes"] = {{{"mesh", 0}}};
    b.doc["scenes"] = {{{"nodes", {0}}}};
    b.doc["scene"] = 0;
    return b;
}

inline std::filesystem::path write_gltf(const std::filesystem::path& path, const nlohmann::json& doc) {
    std::ofstream(path) << doc.dump(1);
    return path;
}

} // namespace nbvh::test
