// Hand-written glTF files (embedded buffers) for features the shared scenes do not cover: sparse accessors,
// triangle strips, a missing and an undecodable texture (warnings, not errors).
#include <cstring>
#include <fstream>

#include <gtest/gtest.h>

#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/scene/gltf_loader.h"
#include "gltf_test_files.h"
#include "scene_checks.h"
#include "tests/support/test_support.h"

namespace {

template <class T>
void put(std::vector<uint8_t>& b, const T& v) {
    const size_t at = b.size();
    b.resize(at + sizeof v);
    std::memcpy(b.data() + at, &v, sizeof v);
}

TEST(GltfFeatures, SparseStripAndBrokenTextures) {
    std::vector<uint8_t> buf;
    for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 1.f, 1.f, 0.f, 0.f, 1.f, 0.f}) put(buf, v); // 0..47 quad
    for (uint16_t i : {0, 1, 3, 2}) put(buf, i);                                              // 48..55 strip
    for (uint8_t i : {1, 0, 0, 0}) put(buf, i);                                               // 56..59 sparse index
    for (float v : {2.f, 0.f, 0.f}) put(buf, v);                                              // 60..71 sparse value
    const std::string json = R"({
  "asset": {"version": "2.0"},
  "scene": 0, "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0, "name": "strip"}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": 5, "material": 0}]}],
  "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}, "normalTexture": {"index": 1}}],
  "textures": [{"source": 0}, {"source": 1}],
  "images": [{"uri": "missing_texture.png"}, {"uri": "data:image/png;base64,AAAAAAAA"}],
  "buffers": [{"byteLength": 72, "uri": "data:application/octet-stream;base64,)" + nbvh::test::base64_of(buf) + R"("}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 8},
                  {"buffer": 0, "byteOffset": 56, "byteLength": 1}, {"buffer": 0, "byteOffset": 60, "byteLength": 12}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,1,0],
     "sparse": {"count": 1, "indices": {"bufferView": 2, "componentType": 5121}, "values": {"bufferView": 3}}},
    {"bufferView": 1, "componentType": 5123, "count": 4, "type": "SCALAR"}]
})";
    const auto path = nbvh::test::temp_dir("scene_features") / "strip.gltf";
    std::ofstream(path) << json;
    nbvh::set_log_level(nbvh::LogLevel::quiet);
    const int warnings_before = nbvh::warning_count();
    const nbvh::Scene s = nbvh::load_gltf(path);
    nbvh::set_log_level(nbvh::LogLevel::info);
    nbvh::test::expect_scene_sane(s);
    ASSERT_EQ(s.meshes.size(), 1u);
    EXPECT_EQ(s.meshes[0].triangle_count(), 2u) << "strip of 4 indices = 2 triangles";
    bool moved = false;
    for (const glm::vec3& p : s.meshes[0].positions) moved |= p == glm::vec3(2, 0, 0);
    EXPECT_TRUE(moved) << "the sparse substitution moves vertex 1 to (2,0,0)";
    // Both strip triangles face +z (winding alternation handled).
    for (const glm::vec3& n : s.meshes[0].normals) EXPECT_GT(n.z, 0.99f);
    EXPECT_EQ(s.materials[0].base_color_tex.texture, -1);
    EXPECT_EQ(s.materials[0].normal_tex.texture, -1);
    EXPECT_TRUE(s.textures.empty());
    EXPECT_GE(nbvh::warning_count() - warnings_before, 2) << "missing and undecodable images warn";
}

TEST(GltfFeatures, AccessorBeyondBufferViewIsAnError) {
    std::vector<uint8_t> buf(36, 0);
    const std::string json = R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
  "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,)" + nbvh::test::base64_of(buf) + R"("}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36, "byteStride": 16}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}]})";
    const auto path = nbvh::test::temp_dir("scene_features_bad") / "stride.gltf";
    std::ofstream(path) << json;
    // 3 elements at stride 16 need 2*16 + 12 = 44 bytes > 36.
    try {
        nbvh::load_gltf(path);
        ADD_FAILURE() << "must throw";
    } catch (const nbvh::Error& e) {
        EXPECT_NE(std::string(e.what()).find("does not fit"), std::string::npos) << e.what();
    }
}

} // namespace
