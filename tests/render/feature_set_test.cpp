// Feature-set derivation: absent effects must not turn on passes or specialization constants.
#include <gtest/gtest.h>

#include <algorithm>

#include "engine/render/feature_set.h"
#include "shaders/shared/scene_gpu.h"
#include "tests/render/test_scenes.h"

namespace nbvh::render {
namespace {

bool has_pass(const std::vector<std::string>& passes, const std::string& name) {
    return std::find(passes.begin(), passes.end(), name) != passes.end();
}

TEST(FeatureSet, PlainSceneWithoutLightsHasNoShadowPass) {
    Scene s = test::make_quad_scene();
    s.materials[0].double_sided = true; // no back-face culling either
    const SceneFeatures f = derive_features(s, Environment{});
    EXPECT_FALSE(f.textures);
    EXPECT_FALSE(f.normal_maps);
    EXPECT_FALSE(f.emission);
    EXPECT_FALSE(f.environment);
    EXPECT_FALSE(f.alpha_mask);
    EXPECT_FALSE(f.transmission);
    EXPECT_FALSE(f.single_sided);
    EXPECT_FALSE(f.has_lights());
    EXPECT_FALSE(has_pass(pass_list(f), "passes/shadow.comp"));
    EXPECT_TRUE(has_pass(pass_list(f), "passes/traverse.comp"));
    for (const vk::SpecConstant& c : specialization(f)) EXPECT_EQ(c.value, 0u) << "constant " << c.id;
}

TEST(FeatureSet, EnvironmentTurnsOnShadowPass) {
    const Scene s = test::make_quad_scene();
    Environment env;
    env.constant = glm::vec3(1.0f);
    const SceneFeatures f = derive_features(s, env);
    EXPECT_TRUE(f.environment);
    EXPECT_FALSE(f.emission);
    EXPECT_TRUE(has_pass(pass_list(f), "passes/shadow.comp"));
    EXPECT_NE(explain(f, 4).find("shadow.comp"), std::string::npos);
}

// KHR_lights_punctual lights alone (no environment, no emitter) switch the shadow pass on; dark ones do not.
TEST(FeatureSet, PunctualLightsTurnOnShadowPass) {
    Scene s = test::make_quad_scene();
    PunctualLight dark;
    dark.intensity = 0.0f;
    s.lights.push_back(dark);
    EXPECT_FALSE(derive_features(s, Environment{}).has_lights());
    s.lights.push_back(PunctualLight{});
    const SceneFeatures f = derive_features(s, Environment{});
    EXPECT_TRUE(f.punctual);
    EXPECT_FALSE(f.environment);
    EXPECT_FALSE(f.emission);
    EXPECT_TRUE(f.has_lights());
    EXPECT_TRUE(has_pass(pass_list(f), "passes/shadow.comp"));
    EXPECT_EQ(specialization(f)[NB_SC_PUNCTUAL_LIGHTS].value, 1u);
    EXPECT_NE(explain(f, 4).find("punctual lights yes"), std::string::npos);
    EXPECT_NE(explain(f, 4).find("shadow.comp"), std::string::npos);
}

TEST(FeatureSet, SingleSidedMaterialsTurnOnBackFaceCulling) {
    Scene s = test::make_quad_scene();
    const SceneFeatures f = derive_features(s, Environment{});
    EXPECT_TRUE(f.single_sided) << "glTF's default material is single-sided";
    EXPECT_EQ(specialization(f)[NB_SC_SINGLE_SIDED].value, 1u);
    s.materials[0].double_sided = true;
    EXPECT_FALSE(derive_features(s, Environment{}).single_sided);
}

TEST(FeatureSet, MaterialsDecideTheirFeatures) {
    Scene s = test::make_quad_scene();
    s.textures.push_back(Texture{"t", 1, 1, {255, 255, 255, 255}});
    s.materials[0].emissive = glm::vec3(2.0f);
    s.materials[0].normal_tex.texture = 0;
    s.materials[0].alpha_mode = AlphaMode::mask;
    s.materials[0].transmission = 1.0f;
    s.materials[0].metallic = 0.0f;
    const SceneFeatures f = derive_features(s, Environment{});
    EXPECT_TRUE(f.textures);
    EXPECT_TRUE(f.normal_maps);
    EXPECT_TRUE(f.emission);
    EXPECT_TRUE(f.alpha_mask);
    EXPECT_TRUE(f.transmission);
    EXPECT_TRUE(f.has_lights());
    const auto spec = specialization(f);
    ASSERT_EQ(spec.size(), size_t(NB_SC_COUNT));
    EXPECT_EQ(spec[NB_SC_EMISSION].value, 1u);
    EXPECT_EQ(spec[NB_SC_NEURAL].value, 0u);
}

// Transmission is weighted by 1 - metallic, metallic = factor x the metallic-roughness texture's B: a
// factor of 1 (glTF's default) with a texture below 1 still transmits (Chess's glass pawn tops: the
// GPU bench-features run found the own and all-forced images 0.0035 FLIP apart).
TEST(FeatureSet, TransmissionCountsTheMetallicTexture) {
    Scene s = test::make_quad_scene();
    s.materials[0].transmission = 1.0f;
    s.materials[0].metallic = 1.0f;
    EXPECT_FALSE(derive_features(s, Environment{}).transmission) << "fully metallic: nothing transmits";
    s.textures.push_back(Texture{"mr", 2, 1, {0, 128, 255, 255, 0, 128, 255, 255}});
    s.materials[0].metallic_roughness_tex.texture = 0;
    EXPECT_FALSE(derive_features(s, Environment{}).transmission) << "metallic texture at 1 everywhere";
    s.textures[0].rgba8[6] = 40; // one texel with metallic 40/255
    EXPECT_TRUE(derive_features(s, Environment{}).transmission);
    s.materials[0].metallic = 0.5f;
    s.materials[0].metallic_roughness_tex.texture = -1;
    EXPECT_TRUE(derive_features(s, Environment{}).transmission);
}

TEST(FeatureSet, UnusedMaterialsAndMissingTexturesDoNotCount) {
    Scene s = test::make_quad_scene();
    Material unused;
    unused.emissive = glm::vec3(5.0f);
    unused.base_color_tex.texture = 0;
    s.materials.push_back(unused);          // no triangle uses it
    s.materials[0].base_color_tex.texture = 7; // no such texture
    const SceneFeatures f = derive_features(s, Environment{});
    EXPECT_FALSE(f.emission);
    EXPECT_FALSE(f.textures);
}

} // namespace
} // namespace nbvh::render
