// The real scenes of ../shared/scenes load with the triangle counts their README states.
#include <gtest/gtest.h>

#include "engine/core/log.h"
#include "engine/scene/gltf_loader.h"
#include "engine/scene/scene_stats.h"
#include "scene_checks.h"
#include "tests/support/test_support.h"

namespace {

using nbvh::Scene;

Scene load_quiet(const std::filesystem::path& rel, const nbvh::SceneLoadOptions& opt = {}) {
    nbvh::set_log_level(nbvh::LogLevel::error);
    Scene s = nbvh::load_gltf(nbvh::test::scenes_dir() / rel, opt);
    nbvh::set_log_level(nbvh::LogLevel::info);
    return s;
}

TEST(GltfRealScenes, FlightHelmet) {
    NBVH_REQUIRE_SHARED();
    const Scene s = load_quiet("flight_helmet/FlightHelmet.gltf");
    nbvh::test::expect_scene_sane(s);
    const nbvh::SceneStats st = nbvh::scene_stats(s);
    EXPECT_EQ(st.triangles, 94722u);
    EXPECT_EQ(st.instanced_triangles, 94722u);
    EXPECT_EQ(st.meshes, 6u);
    EXPECT_EQ(st.textures, 15u);
    // Normal-mapped materials: every mesh has tangents; base colour textures are flagged sRGB.
    for (const nbvh::Mesh& m : s.meshes) EXPECT_FALSE(m.tangents.empty()) << m.name;
    int srgb = 0, blend = 0;
    for (const nbvh::Texture& t : s.textures) srgb += t.srgb;
    for (const nbvh::Material& m : s.materials) blend += m.alpha_mode != nbvh::AlphaMode::opaque;
    EXPECT_GT(srgb, 0);
    EXPECT_LT(srgb, 15);
    EXPECT_GT(blend, 0) << "the lenses are alpha-blended";
    EXPECT_EQ(s.materials.back().name, "default");
}

TEST(GltfRealScenes, StanfordBunnyPositionsOnly) {
    NBVH_REQUIRE_SHARED();
    const Scene s = load_quiet("stanford_bunny/stanford_bunny.glb");
    nbvh::test::expect_scene_sane(s);
    EXPECT_EQ(nbvh::scene_stats(s).instanced_triangles, 69451u);
    ASSERT_EQ(s.meshes.size(), 1u);
    EXPECT_TRUE(s.meshes[0].tangents.empty()) << "no normal map, no tangents";
    EXPECT_TRUE(s.meshes[0].uv0.empty());
}

TEST(GltfRealScenes, SheenClothTextureTransform) {
    NBVH_REQUIRE_SHARED();
    const Scene s = load_quiet("sheen_cloth/SheenCloth.gltf");
    nbvh::test::expect_scene_sane(s);
    EXPECT_EQ(nbvh::scene_stats(s).instanced_triangles, 115200u);
    bool transformed = false;
    for (const nbvh::Material& m : s.materials)
        for (const nbvh::TextureRef* r : {&m.base_color_tex, &m.normal_tex, &m.metallic_roughness_tex})
            if (r->texture >= 0 && r->transform != glm::mat3(1.0f)) transformed = true;
    EXPECT_TRUE(transformed) << "KHR_texture_transform (tiling) must reach TextureRef::transform";
}

TEST(GltfRealScenes, SmithsonianGetsGeneratedTangents) {
    NBVH_REQUIRE_SHARED();
    const Scene s = load_quiet("smithsonian_usnm1145291/usnm_1145291.glb");
    nbvh::test::expect_scene_sane(s);
    EXPECT_EQ(nbvh::scene_stats(s).instanced_triangles, 100000u);
    ASSERT_EQ(s.meshes.size(), 1u);
    const nbvh::Mesh& m = s.meshes[0];
    ASSERT_EQ(m.tangents.size(), m.positions.size()) << "normal map without TANGENT: tangents are generated";
    size_t not_orthogonal = 0;
    for (size_t v = 0; v < m.tangents.size(); ++v)
        not_orthogonal += std::fabs(glm::dot(glm::vec3(m.tangents[v]), m.normals[v])) > 1e-3f;
    EXPECT_EQ(not_orthogonal, 0u);

    nbvh::SceneLoadOptions geometry_only;
    geometry_only.keep_textures = false;
    const Scene g = load_quiet("smithsonian_usnm1145291/usnm_1145291.glb", geometry_only);
    EXPECT_TRUE(g.textures.empty());
    EXPECT_TRUE(g.meshes[0].tangents.empty());
    EXPECT_EQ(g.meshes[0].triangle_count(), 100000u);
}

// 28 MB: loaded here and by FeatureForce.ChessGlassPawnTopsTransmitInTheirOwnRender (tests/render).
TEST(GltfRealScenes, ChessInstancingAndNeuralScene) {
    NBVH_REQUIRE_SHARED();
    Scene s = load_quiet("abeautifulgame/abeautifulgame.glb");
    nbvh::test::expect_scene_sane(s);
    nbvh::SceneStats st = nbvh::scene_stats(s);
    EXPECT_EQ(st.meshes, 15u);
    EXPECT_EQ(st.instances, 49u);
    EXPECT_EQ(st.triangles, 565848u);            // each glTF mesh once (README: 565,848)
    EXPECT_EQ(st.instanced_triangles, 1430784u); // README: `scene`
    EXPECT_EQ(st.neural_triangles, 1338368u);    // README: `scene_neural`
    EXPECT_EQ(st.neural_instances, 48u);
    for (const nbvh::Instance& inst : s.instances)
        EXPECT_EQ(inst.neural, inst.name != "Chessboard") << inst.name;
    bool transmission = false;
    for (const nbvh::Material& m : s.materials) transmission |= m.transmission > 0.0f;
    EXPECT_TRUE(transmission) << "pawn tops use KHR_materials_transmission";

    // --neural glob overrides the scene convention.
    nbvh::mark_neural_by_glob(s, "Pawn_Top_?1");
    st = nbvh::scene_stats(s);
    EXPECT_EQ(st.neural_instances, 2u); // Pawn_Top_B1, Pawn_Top_W1
    EXPECT_EQ(st.neural_triangles, 2u * 2208u);
}

} // namespace
