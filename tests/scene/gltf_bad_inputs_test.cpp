// Every file in ../shared/scenes/bad/ against bad/generated/expected.json and bad/README.md: a clear
// nbvh::Error naming the problem, or a scene without the bad parts (and a warning).
#include <fstream>
#include <map>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/scene/gltf_loader.h"
#include "engine/scene/scene_stats.h"
#include "scene_checks.h"
#include "tests/support/test_support.h"

namespace {

using nbvh::Scene;

struct Quiet {
    Quiet() { nbvh::set_log_level(nbvh::LogLevel::quiet); }
    ~Quiet() { nbvh::set_log_level(nbvh::LogLevel::info); }
};

std::filesystem::path bad_dir() { return nbvh::test::scenes_dir() / "bad"; }

// Loads or returns the error message (empty on success).
std::string try_load(const std::filesystem::path& p, Scene& out, const nbvh::SceneLoadOptions& opt = {}) {
    try {
        out = nbvh::load_gltf(p, opt);
        return "";
    } catch (const nbvh::Error& e) {
        std::string msg = e.what();
        EXPECT_FALSE(msg.empty());
        EXPECT_EQ(msg.find('\n'), std::string::npos) << "error must be one line: " << msg;
        return msg;
    }
}

uint64_t instanced(const Scene& s) { return nbvh::scene_stats(s).instanced_triangles; }

// What the error message of each "error" file must mention (the problem, or the file it concerns).
const std::map<std::string, std::string> ERROR_WORDS = {
    {"bad_magic.glb", "not a GLB"},
    {"broken_json.gltf", "parse error"},
    {"huge_count.gltf", "count 2000000000"},
    {"missing_buffer.gltf", "this_file_does_not_exist.bin"},
    {"scene_index_out_of_range.gltf", "scene 3 does not exist"},
    {"short_buffer.gltf", "short_buffer.bin"},
    {"truncated.glb", "truncated GLB"},
};

// Triangle counts (instanced) of the files that must load and render.
const std::map<std::string, uint64_t> RENDER_TRIANGLES = {
    {"degenerate_triangles.gltf", 6}, {"flat_aabb.gltf", 2}, {"valid_quad.glb", 2}, {"valid_uncommon_layout.gltf", 8},
    {"nan_positions.gltf", 2},        {"inf_positions.glb", 2},
};

TEST(GltfBadInputs, GeneratedFilesBehaveAsExpectedJson) {
    NBVH_REQUIRE_SHARED();
    Quiet quiet;
    std::ifstream in(bad_dir() / "generated" / "expected.json");
    ASSERT_TRUE(in) << "expected.json missing";
    const nlohmann::json expected = nlohmann::json::parse(in);
    ASSERT_GE(expected.size(), 19u);
    for (const auto& [name, entry] : expected.items()) {
        SCOPED_TRACE(name);
        const std::string expect = entry.at("expect");
        Scene scene;
        const int warnings_before = nbvh::warning_count();
        const std::string err = try_load(bad_dir() / "generated" / name, scene);
        const bool warned = nbvh::warning_count() > warnings_before;
        if (err.empty()) nbvh::test::expect_scene_sane(scene);
        if (expect == "error") {
            ASSERT_FALSE(err.empty()) << "must fail with a clear error";
            ASSERT_TRUE(ERROR_WORDS.count(name)) << "no expected wording for " << name;
            EXPECT_NE(err.find(ERROR_WORDS.at(name)), std::string::npos) << err;
        } else if (expect == "load_render") {
            if (name == "far_from_origin.gltf") {
                // The file's float32 vertices are all exactly 1e6 (the 1 cm offset is below the float spacing
                // of 0.0625 there), so its "quad" has zero area: it loads, warned, with nothing to render.
                EXPECT_TRUE(err.empty()) << err;
                EXPECT_TRUE(warned);
                continue;
            }
            ASSERT_TRUE(err.empty()) << err;
            EXPECT_EQ(instanced(scene), RENDER_TRIANGLES.at(name));
        } else if (expect == "load_skip_bad") {
            ASSERT_TRUE(err.empty()) << err;
            EXPECT_EQ(instanced(scene), RENDER_TRIANGLES.at(name));
            EXPECT_TRUE(warned) << "dropping triangles must warn";
            const nbvh::Aabb b = scene.world_bounds();
            EXPECT_EQ(b.lo, glm::vec3(0.0f));
            EXPECT_EQ(b.hi, glm::vec3(1.0f, 1.0f, 0.0f));
        } else if (expect == "load_empty_or_error") {
            if (err.empty()) {
                EXPECT_EQ(instanced(scene), 0u);
                EXPECT_TRUE(warned);
            }
        } else if (expect == "error_or_skip") {
            if (err.empty()) {
                EXPECT_EQ(instanced(scene), 1u); // index_out_of_range: one of two triangles survives
                EXPECT_TRUE(warned);
            }
        } else if (expect == "load_or_clear_error") {
            if (!err.empty()) {
                EXPECT_NE(err.find("out of range"), std::string::npos) << err;
            } else {
                EXPECT_GT(instanced(scene), 0u);
            }
        } else {
            ADD_FAILURE() << "unknown expectation " << expect;
        }
    }
}

TEST(GltfBadInputs, UncommonLayoutHasFourQuadsWithMirroredInstance) {
    NBVH_REQUIRE_SHARED();
    Quiet quiet;
    const Scene s = nbvh::load_gltf(bad_dir() / "generated" / "valid_uncommon_layout.gltf");
    ASSERT_EQ(s.instances.size(), 4u);
    int mirrored = 0;
    std::vector<std::pair<float, float>> x_ranges;
    for (const nbvh::Instance& inst : s.instances) {
        mirrored += glm::determinant(glm::mat3(inst.object_to_world)) < 0.0f;
        nbvh::Aabb b;
        for (const glm::vec3& p : s.meshes[inst.mesh].positions) b.grow(glm::vec3(inst.object_to_world * glm::vec4(p, 1)));
        x_ranges.push_back({b.lo.x, b.hi.x});
        EXPECT_EQ(s.meshes[inst.mesh].triangle_count(), 2u);
    }
    EXPECT_EQ(mirrored, 1);
    std::sort(x_ranges.begin(), x_ranges.end());
    const std::vector<std::pair<float, float>> want = {{0, 1}, {0, 1}, {2, 3}, {4, 5}};
    for (size_t i = 0; i < want.size(); ++i) {
        EXPECT_NEAR(x_ranges[i].first, want[i].first, 1e-5f);
        EXPECT_NEAR(x_ranges[i].second, want[i].second, 1e-5f);
    }
}

TEST(GltfBadInputs, RequireGeometryTurnsEmptyIntoError) {
    NBVH_REQUIRE_SHARED();
    Quiet quiet;
    nbvh::SceneLoadOptions opt;
    opt.require_geometry = true;
    for (const char* name : {"empty_scene.gltf", "lines_only.gltf", "zero_area_mesh.gltf"}) {
        Scene s;
        const std::string err = try_load(bad_dir() / "generated" / name, s, opt);
        EXPECT_NE(err.find("no renderable geometry"), std::string::npos) << name << ": " << err;
    }
}

// bad/assimp: expectations from bad/README.md (no machine-readable file there).
TEST(GltfBadInputs, AssimpFilesBehaveAsReadme) {
    NBVH_REQUIRE_SHARED();
    Quiet quiet;
    struct Case {
        const char* path;
        const char* error_word;   // non-null: must throw mentioning this
        int64_t triangles;        // else: instanced triangles after loading (-1: don't care)
    };
    const Case cases[] = {
        {"BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb", nullptr, 0},
        {"BoxBadNormals-glTF-Binary/BoxBadNormals.glb", nullptr, 12},
        {"IncorrectVertexArrays/Cube.gltf", nullptr, -1},
        {"IndexOutOfRange/IndexOutOfRange.gltf", nullptr, 11},
        {"IndexOutOfRange/AllIndicesOutOfRange.gltf", nullptr, 0},
        {"MissingBin/BoxTextured.gltf", "BoxTextured0.bin", 0},
        {"RecursiveNodes/RecursiveNodes.gltf", "cycle", 0},
        {"TestNoRootNode/NoScene.gltf", "scene 0 does not exist", 0},
        {"TestNoRootNode/SceneWithoutNodes.gltf", nullptr, 0},
        {"wrongTypes/badArray.gltf", "primitives", 0},
        {"wrongTypes/badNumber.gltf", nullptr, 12},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.path);
        Scene s;
        const int warnings_before = nbvh::warning_count();
        const std::string err = try_load(bad_dir() / "assimp" / c.path, s);
        if (c.error_word) {
            EXPECT_NE(err.find(c.error_word), std::string::npos) << "got: '" << err << "'";
            continue;
        }
        ASSERT_TRUE(err.empty()) << err;
        nbvh::test::expect_scene_sane(s);
        if (c.triangles >= 0) {
            EXPECT_EQ(instanced(s), uint64_t(c.triangles));
        }
        EXPECT_GT(nbvh::warning_count(), warnings_before) << "a repaired or skipped input must warn";
    }
}

TEST(GltfBadInputs, MissingFileIsAClearError) {
    Scene s;
    const std::string err = try_load("/nonexistent/dir/scene.gltf", s);
    EXPECT_NE(err.find("cannot open"), std::string::npos) << err;
}

} // namespace
