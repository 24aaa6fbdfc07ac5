// Unsupported glTF extensions and ignored features are named once (issue 12): one warning per extension
// whatever the number of objects using it, an unsupported required extension is a one-line error (also
// when tinygltf cannot read the file without it), supported ones load silently.
#include <gtest/gtest.h>

#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/scene/gltf_loader.h"
#include "gltf_test_files.h"
#include "tests/support/test_support.h"

namespace {

namespace fs = std::filesystem;
using nbvh::test::quad_gltf;
using nbvh::test::write_gltf;

// Loads `path` with warnings on, returning the stderr lines (load errors propagate).
std::vector<std::string> load_logged(const fs::path& path, nbvh::Scene* out = nullptr) {
    nbvh::set_log_level(nbvh::LogLevel::warn);
    testing::internal::CaptureStderr();
    std::string err;
    try {
        nbvh::Scene s = nbvh::load_gltf(path);
        if (out) *out = std::move(s);
    } catch (...) {
        err = testing::internal::GetCapturedStderr();
        nbvh::set_log_level(nbvh::LogLevel::info);
        throw;
    }
    err = testing::internal::GetCapturedStderr();
    nbvh::set_log_level(nbvh::LogLevel::info);
    std::vector<std::string> lines;
    size_t start = 0;
    while (start < err.size()) {
        const size_t end = err.find('\n', start);
        lines.push_back(err.substr(start, end - start));
        if (end == std::string::npos) break;
        start = end + 1;
    }
    return lines;
}

size_t lines_with(const std::vector<std::string>& lines, const std::string& word) {
    size_t n = 0;
    for (const std::string& l : lines) n += l.find(word) != std::string::npos;
    return n;
}

std::string load_error(const fs::path& path) {
    try {
        nbvh::set_log_level(nbvh::LogLevel::quiet);
        nbvh::load_gltf(path);
    } catch (const nbvh::Error& e) {
        nbvh::set_log_level(nbvh::LogLevel::info);
        return e.what();
    }
    nbvh::set_log_level(nbvh::LogLevel::info);
    return "";
}

TEST(GltfSupport, EachUnsupportedExtensionIsNamedOnce) {
    const fs::path dir = nbvh::test::temp_dir("gltf_support_once");
    nbvh::test::GltfBuilder b = quad_gltf();
    // Three materials with sheen, two nodes with GPU instancing, one undeclared made-up extension, two
    // supported ones (lights on two nodes).
    b.doc["extensionsUsed"] = {"KHR_materials_sheen", "EXT_mesh_gpu_instancing", "KHR_texture_transform",
                               "KHR_lights_punctual"};
    b.doc["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}}};
    for (int m = 0; m < 3; ++m)
        b.doc["materials"].push_back({{"extensions", {{"KHR_materials_sheen", {{"sheenRoughnessFactor", 0.5}}}}}});
    b.doc["meshes"][0]["primitives"][0]["material"] = 2;
    const nlohmann::json instancing = {{"attributes", nlohmann::json::object()}};
    b.doc["nodes"] = {{{"mesh", 0},
                       {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}, {"EXT_mesh_gpu_instancing", instancing}}}},
                      {{"mesh", 0},
                       {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}, {"EXT_mesh_gpu_instancing", instancing}}}},
                      {{"mesh", 0}, {"extensions", {{"EXT_made_up", nlohmann::json::object()}}}}};
    b.doc["scenes"] = {{{"nodes", {0, 1, 2}}}};
    nbvh::Scene s;
    const std::vector<std::string> lines = load_logged(write_gltf(dir / "ext.gltf", b.finish()), &s);
    EXPECT_EQ(s.instances.size(), 3u) << "the scene still loads";
    EXPECT_EQ(lines_with(lines, "KHR_materials_sheen"), 1u);
    EXPECT_EQ(lines_with(lines, "EXT_mesh_gpu_instancing"), 1u);
    EXPECT_EQ(lines_with(lines, "EXT_made_up"), 1u) << "undeclared extensions are named too";
    EXPECT_EQ(lines_with(lines, "KHR_texture_transform"), 0u) << "supported: no line";
    EXPECT_EQ(lines_with(lines, "KHR_lights_punctual"), 0u) << "supported: no line";
    EXPECT_EQ(s.lights.size(), 2u);
    for (const std::string& l : lines) EXPECT_EQ(l.rfind("warning: ", 0), 0u) << l;
}

TEST(GltfSupport, IgnoredCoreFeaturesAreNamedOnce) {
    const fs::path dir = nbvh::test::temp_dir("gltf_support_features");
    nbvh::test::GltfBuilder b = quad_gltf();
    const int colours = b.add(std::vector<float>(16, 0.5f), 5126, "VEC4");
    b.doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = colours;
    b.doc["meshes"][0]["primitives"].push_back(b.doc["meshes"][0]["primitives"][0]);
    b.doc["samplers"] = {{{"wrapS", 33071}, {"wrapT", 33071}}, {{"wrapS", 33648}}};
    const std::vector<std::string> lines = load_logged(write_gltf(dir / "features.gltf", b.finish()));
    EXPECT_EQ(lines_with(lines, "COLOR_0"), 1u) << "one line for both primitives";
    EXPECT_EQ(lines_with(lines, "sampler"), 1u) << "one line for both samplers";
}

TEST(GltfSupport, UnsupportedRequiredExtensionIsAOneLineError) {
    const fs::path dir = nbvh::test::temp_dir("gltf_support_required");
    nbvh::test::GltfBuilder b = quad_gltf();
    b.doc["extensionsUsed"] = {"KHR_draco_mesh_compression", "KHR_texture_transform"};
    b.doc["extensionsRequired"] = {"KHR_draco_mesh_compression", "KHR_texture_transform"};
    const std::string err = load_error(write_gltf(dir / "draco.gltf", b.finish()));
    EXPECT_NE(err.find("requires extension KHR_draco_mesh_compression"), std::string::npos) << err;
    EXPECT_EQ(err.find("KHR_texture_transform"), std::string::npos) << "supported: not named: " << err;
    EXPECT_EQ(err.find('\n'), std::string::npos) << err;

    // EXT_meshopt_compression's fallback buffer has no uri, which tinygltf rejects: the error still names the
    // extension rather than the missing uri.
    nlohmann::json d = quad_gltf().finish();
    d["extensionsUsed"] = d["extensionsRequired"] = {"EXT_meshopt_compression"};
    d["buffers"].push_back({{"byteLength", 48}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}});
    const std::string err2 = load_error(write_gltf(dir / "meshopt.gltf", d));
    EXPECT_NE(err2.find("requires extension EXT_meshopt_compression"), std::string::npos) << err2;
}

TEST(GltfSupport, SupportedRequiredExtensionLoadsSilently) {
    // KHR_mesh_quantization: SHORT positions (not normalized), scaled by the node to a 2 m quad.
    const fs::path dir = nbvh::test::temp_dir("gltf_support_quantized");
    nbvh::test::GltfBuilder b;
    const int pos = b.add(std::vector<int16_t>{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, 5122, "VEC3");
    b.doc["accessors"][size_t(pos)]["min"] = {0, 0, 0};
    b.doc["accessors"][size_t(pos)]["max"] = {1, 1, 0};
    const int idx = b.add(std::vector<uint8_t>{0, 1, 2, 0, 2, 3}, 5121, "SCALAR");
    b.doc["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", pos}}}, {"indices", idx}}}}}};
    b.doc["nodes"] = {{{"mesh", 0}, {"scale", {2, 2, 2}}}};
    b.doc["scenes"] = {{{"nodes", {0}}}};
    b.doc["extensionsUsed"] = b.doc["extensionsRequired"] = {"KHR_mesh_quantization"};
    nbvh::Scene s;
    const std::vector<std::string> lines = load_logged(write_gltf(dir / "quantized.gltf", b.finish()), &s);
    EXPECT_EQ(lines_with(lines, "warning"), 0u);
    ASSERT_EQ(s.meshes.size(), 1u);
    EXPECT_EQ(s.meshes[0].triangle_count(), 2u);
    EXPECT_EQ(s.world_bounds().hi, glm::vec3(2.0f, 2.0f, 0.0f));
}

} // namespace

// Images that share one bufferView are decoded once and share one texture (fuzzing found a 261 KB file
// whose 8 images point at one 8192^2 PNG: 2.9 GB and 10 s before); see gltf_material.h.
TEST(GltfSupport, ImagesSharingBytesAreDecodedOnce) {
    const std::vector<uint8_t> png = {0x89, 0x50, 0x4E, 0x47, 0x0D, 0x0A, 0x1A, 0x0A, 0x00, 0x00, 0x00, 0x0D, 0x49,
                                      0x48, 0x44, 0x52, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x08, 0x02,
                                      0x00, 0x00, 0x00, 0x90, 0x77, 0x53, 0xDE, 0x00, 0x00, 0x00, 0x0C, 0x49, 0x44,
                                      0x41, 0x54, 0x08, 0xD7, 0x63, 0xF8, 0xCF, 0xC0, 0x00, 0x00, 0x03, 0x01, 0x01,
                                      0x00, 0x18, 0xDD, 0x8D, 0xB0, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4E, 0x44,
                                      0xAE, 0x42, 0x60, 0x82};
    nbvh::test::GltfBuilder b = quad_gltf();
    b.add(png, 5121, "SCALAR");
    const int view = int(b.doc["bufferViews"].size()) - 1;
    for (int i = 0; i < 8; ++i) {
        b.doc["images"].push_back({{"bufferView", view}, {"mimeType", "image/png"}});
        b.doc["textures"].push_back({{"source", i}});
        b.doc["materials"].push_back({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", i}}}}}});
    }
    b.doc["meshes"][0]["primitives"][0]["material"] = 7;
    const auto path = write_gltf(fs::temp_directory_path() / "nbvh_shared_images.gltf", b.finish());
    const nbvh::Scene s = nbvh::load_gltf(path);
    fs::remove(path);
    ASSERT_EQ(s.textures.size(), 1u); // one decode, one texture
    EXPECT_EQ(s.textures[0].width, 1u);
    for (size_t m = 0; m < 8; ++m) EXPECT_EQ(s.materials[m].base_color_tex.texture, 0) << m;
}
