// Skins and morph targets load at the pose a glTF viewer shows without animation (issue 12): a two-joint
// skin with a rotated joint gives exactly the same world-space triangles as the mesh pre-posed by hand,
// morph targets apply at their default weights, bad skins degrade with a warning, and one info line says so.
#include <cmath>

#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

#include "engine/core/log.h"
#include "engine/scene/gltf_loader.h"
#include "gltf_test_files.h"
#include "scene_checks.h"
#include "tests/support/test_support.h"

namespace {

namespace fs = std::filesystem;
using nbvh::test::GltfBuilder;
using nbvh::test::write_gltf;

// A 1 x 2 strip in the plane z = 3 (rows y = 0, 1, 2; x = 0, 1): the mesh of the skin test, in bind space.
const std::vector<float> STRIP = {0, 0, 3, 1, 0, 3, 0, 1, 3, 1, 1, 3, 0, 2, 3, 1, 2, 3};
const std::vector<uint16_t> STRIP_INDICES = {0, 1, 3, 0, 3, 2, 2, 3, 5, 2, 5, 4};

// Armature node 0 at (0,0,3) with joint 1 (no transform) and joint 2 (child of 1, at y = 1, rotated 90
// degrees about z); the skinned mesh node 3 is a child of the armature and has its own transform, which
// glTF says must be ignored. Bottom row on joint 1, middle row half/half, top row on joint 2.
nlohmann::json skinned_strip(int bad_joint = -1) {
    GltfBuilder b;
    const int pos = b.add_positions(STRIP);
    const int idx = b.add(STRIP_INDICES, 5123, "SCALAR");
    std::vector<uint8_t> joints = {0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    if (bad_joint >= 0) joints[size_t(4 * bad_joint)] = 7; // a joint the skin does not have
    const int ja = b.add(joints, 5121, "VEC4");
    const int wa = b.add(std::vector<float>{1,    0,    0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0,
                                            0.5f, 0.5f, 0, 0, 1, 0, 0, 0, 1,    0,    0, 0},
                         5126, "VEC4");
    // Inverse bind matrices (column-major): the joints' bind-pose world transforms T(0,0,3), T(0,1,3)
    // inverted.
    std::vector<float> ibm(32, 0.0f);
    for (int j = 0; j < 2; ++j) {
        for (int d = 0; d < 4; ++d) ibm[size_t(16 * j + 5 * d)] = 1.0f;
        ibm[size_t(16 * j + 13)] = -float(j);
        ibm[size_t(16 * j + 14)] = -3.0f;
    }
    const int ibm_accessor = b.add(ibm, 5126, "MAT4");
    b.doc["meshes"] = {
        {{"name", "strip"},
         {"primitives",
          {{{"attributes", {{"POSITION", pos}, {"JOINTS_0", ja}, {"WEIGHTS_0", wa}}}, {"indices", idx}}}}}};
    const double s = std::sqrt(0.5); // quaternion (x, y, z, w) of 90 degrees about +z
    b.doc["nodes"] = {{{"name", "armature"}, {"translation", {0, 0, 3}}, {"children", {1, 3}}},
                      {{"name", "root_joint"}, {"children", {2}}},
                      {{"name", "tip_joint"}, {"translation", {0, 1, 0}}, {"rotation", {0, 0, s, s}}},
                      {{"name", "skinned"}, {"mesh", 0}, {"skin", 0}, {"translation", {100, 0, 0}}}};
    b.doc["skins"] = {{{"joints", {1, 2}}, {"inverseBindMatrices", ibm_accessor}}};
    b.doc["scenes"] = {{{"nodes", {0}}}};
    return b.finish();
}

// The same strip posed by hand: joint 2's world transform is T(0,1,3) R(90 z), so a top-row vertex
// (x, 2, 3) goes to T(0,1,3) R (x, 1, 0) = (-1, 1 + x, 3); the middle row blends (x, 1, 3) and (0, 1 + x, 3).
nlohmann::json preposed_strip() {
    GltfBuilder b;
    const int pos = b.add_positions({0, 0, 3, 1, 0, 3, 0, 1, 3, 0.5f, 1.5f, 3, -1, 1, 3, -1, 2, 3});
    const int idx = b.add(STRIP_INDICES, 5123, "SCALAR");
    b.doc["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", pos}}}, {"indices", idx}}}}}};
    b.doc["nodes"] = {{{"mesh", 0}}};
    b.doc["scenes"] = {{{"nodes", {0}}}};
    return b.finish();
}

// World-space corners of every triangle of every instance, in order.
std::vector<glm::vec3> world_corners(const nbvh::Scene& s) {
    std::vector<glm::vec3> out;
    for (const nbvh::Instance& inst : s.instances) {
        const nbvh::Mesh& m = s.meshes[inst.mesh];
        for (uint32_t i : m.indices)
            out.push_back(glm::vec3(inst.object_to_world * glm::vec4(m.positions[i], 1.0f)));
    }
    return out;
}

nbvh::Scene load_quiet(const fs::path& path, std::string* log = nullptr) {
    nbvh::set_log_level(log ? nbvh::LogLevel::info : nbvh::LogLevel::quiet);
    if (log) testing::internal::CaptureStderr();
    nbvh::Scene s = nbvh::load_gltf(path);
    if (log) *log = testing::internal::GetCapturedStderr();
    nbvh::set_log_level(nbvh::LogLevel::info);
    return s;
}

size_t count(const std::string& text, const std::string& word) {
    size_t n = 0;
    for (size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) ++n;
    return n;
}

TEST(GltfPose, SkinnedMeshMatchesTheMeshPreposedByHand) {
    const fs::path dir = nbvh::test::temp_dir("gltf_pose_skin");
    std::string log;
    const nbvh::Scene skinned = load_quiet(write_gltf(dir / "skinned.gltf", skinned_strip()), &log);
    const nbvh::Scene preposed = load_quiet(write_gltf(dir / "preposed.gltf", preposed_strip()));
    nbvh::test::expect_scene_sane(skinned);
    const std::vector<glm::vec3> a = world_corners(skinned), b = world_corners(preposed);
    ASSERT_EQ(a.size(), b.size());
    ASSERT_EQ(a.size(), 12u);
    for (size_t i = 0; i < a.size(); ++i) EXPECT_LT(glm::distance(a[i], b[i]), 1e-5f) << "corner " << i;
    // Normals follow the geometry: the strip stays in z = 3, so they are +-z everywhere.
    for (const glm::vec3& n : skinned.meshes[0].normals) EXPECT_NEAR(std::fabs(n.z), 1.0f, 1e-5f);
    EXPECT_EQ(skinned.instances[0].name, "skinned");
    EXPECT_EQ(count(log, "skinned instance"), 1u) << "one info line says the skin is posed:\n" << log;
    EXPECT_EQ(count(log, "warning"), 0u) << log;
}

TEST(GltfPose, BadSkinInfluencesDegradeWithAWarning) {
    const fs::path dir = nbvh::test::temp_dir("gltf_pose_bad_skin");
    // Vertex 0's only influence names joint 7: it is placed by the node's transform, the rest is skinned.
    std::string log;
    const nbvh::Scene s = load_quiet(write_gltf(dir / "bad_joint.gltf", skinned_strip(0)), &log);
    nbvh::test::expect_scene_sane(s);
    EXPECT_EQ(count(log, "warning: "), 2u) << "the bad influence and the unweighted vertex, once each:\n"
                                           << log;
    // A skin whose joint does not exist: the whole mesh is rendered unskinned (node transform), warned.
    nlohmann::json d = skinned_strip();
    d["skins"][0]["joints"] = {1, 9};
    log.clear();
    const nbvh::Scene u = load_quiet(write_gltf(dir / "missing_joint.gltf", d), &log);
    nbvh::test::expect_scene_sane(u);
    EXPECT_EQ(count(log, "warning: "), 1u) << log;
    ASSERT_EQ(u.instances.size(), 1u);
    EXPECT_EQ(glm::vec3(u.instances[0].object_to_world[3]), glm::vec3(100, 0, 3));
}

TEST(GltfPose, MorphTargetsAtTheirDefaultWeights) {
    const fs::path dir = nbvh::test::temp_dir("gltf_pose_morph");
    GltfBuilder b = nbvh::test::quad_gltf();
    // One target lifting vertex 2 by 1 in z; the mesh's default weight 0.5, node 1 overrides with 1.
    const int delta = b.add_positions({0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0});
    b.doc["meshes"][0]["primitives"][0]["targets"] = {{{"POSITION", delta}}};
    b.doc["meshes"][0]["weights"] = {0.5};
    b.doc["nodes"] = {{{"name", "half"}, {"mesh", 0}},
                      {{"name", "full"}, {"mesh", 0}, {"weights", {1.0}}, {"translation", {2, 0, 0}}},
                      {{"name", "half_again"}, {"mesh", 0}, {"translation", {4, 0, 0}}}};
    b.doc["scenes"] = {{{"nodes", {0, 1, 2}}}};
    std::string log;
    const nbvh::Scene s = load_quiet(write_gltf(dir / "morph.gltf", b.finish()), &log);
    nbvh::test::expect_scene_sane(s);
    ASSERT_EQ(s.instances.size(), 3u);
    EXPECT_EQ(s.meshes.size(), 2u) << "nodes without weights of their own share the mesh";
    EXPECT_EQ(s.instances[0].mesh, s.instances[2].mesh);
    auto top_z = [&](size_t i) {
        float z = 0.0f;
        for (const glm::vec3& p : s.meshes[s.instances[i].mesh].positions) z = std::max(z, p.z);
        return z;
    };
    EXPECT_FLOAT_EQ(top_z(0), 0.5f);
    EXPECT_FLOAT_EQ(top_z(1), 1.0f);
    EXPECT_EQ(count(log, "morphed"), 1u) << log;
}

} // namespace
