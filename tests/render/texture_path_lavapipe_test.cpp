// The texture path on lavapipe (no descriptor indexing in Debian 12's Mesa): auto renders through the texel
// buffer with zero validation messages and says so in its stats; asking for the array is a clear error.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "engine/bvh/scene_accel.h"
#include "engine/core/error.h"
#include "engine/render/wavefront.h"
#include "engine/scene/environment.h"
#include "engine/vk/context.h"
#include "tests/render/test_scenes.h"

namespace nbvh::render {
namespace {

TEST(TexturePathLavapipe, AutoIsTheBufferPathAndArrayIsRefused) {
    vk::ContextOptions o;
    o.device = vk::DeviceChoice::cpu;
    o.validation = true;
    vk::Context ctx(o);
    if (texture_array_unavailable(texture_caps(ctx.features())).empty())
        GTEST_SKIP() << "this lavapipe has descriptor indexing (Debian 12's has not): the premise does not hold";
    const Scene scene = test::make_textured_scene();
    const SceneAccel accel = build_scene_accel(scene);
    const Environment env = constant_environment(glm::vec3(0.6f, 0.7f, 0.9f));
    RenderOptions opt;
    opt.width = 48;
    opt.height = 32;
    opt.spp = 2;
    opt.max_depth = 3;
    WavefrontRenderer r(ctx, scene, accel, env, scene.camera, opt);
    EXPECT_TRUE(r.features().textures);
    EXPECT_TRUE(r.features().normal_maps);
    EXPECT_TRUE(r.features().alpha_mask);
    EXPECT_EQ(r.texture_plan().path, TexturePath::buffer);
    const RenderResult res = r.render();
    EXPECT_EQ(res.stats.texture_path, "buffer");
    EXPECT_EQ(res.stats.texture_count, 5u);
    EXPECT_EQ(res.stats.texture_bytes, uint64_t(r.scene_data().texels.size()) * 4);
    EXPECT_EQ(res.stats.texture_bytes, (64u * 48u + 32u * 32u * 3u + 16u * 24u) * 4u);
    EXPECT_EQ(res.stats.texture_halvings, 0u);
    EXPECT_EQ(res.stats.nonfinite_pixels, 0u);
    EXPECT_TRUE(ctx.validation_enabled()) << "the Khronos validation layer must be installed for this test";
    EXPECT_EQ(ctx.validation_message_count(), 0);

    opt.texture_path = TexturePathRequest::array;
    try {
        WavefrontRenderer refused(ctx, scene, accel, env, scene.camera, opt);
        FAIL() << "the array path needs descriptor indexing";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("--texture-path buffer"), std::string::npos) << e.what();
    }
}

} // namespace
} // namespace nbvh::render
