// The texture path (engine/render/texture_path.h) as pure functions of the device's features: the choice,
// the buffer path's halvings (as pack_scene applies them), the array path's limits; and the shader build's
// texture-array variants (shaders/CMakeLists.txt) checked against the SPIR-V of every pass.
#include <gtest/gtest.h>

#include <algorithm>
#include <span>
#include <string>
#include <vector>

#include "engine/bvh/scene_accel.h"
#include "engine/core/error.h"
#include "engine/render/gpu_scene.h"
#include "engine/render/texture_path.h"
#include "shaders/shader_registry.h"
#include "shaders/shared/scene_gpu.h"
#include "tests/render/test_scenes.h"

namespace nbvh::render {
namespace {

// Debian 12's lavapipe: no descriptor indexing.
TextureCaps lavapipe_caps() {
    TextureCaps c;
    c.max_sampled_images = 1u << 20;
    c.max_per_stage_resources = 1u << 20;
    c.max_image_dimension_2d = 16384;
    c.max_memory_allocations = 1u << 20;
    c.max_storage_buffer_range = 128ull << 20;
    return c;
}

TextureCaps indexing_caps() {
    TextureCaps c = lavapipe_caps();
    c.runtime_descriptor_array = true;
    c.sampled_image_array_nonuniform = true;
    c.max_storage_buffer_range = 4ull << 30;
    return c;
}

Texture texture(uint32_t w, uint32_t h, const std::string& name = "t") {
    Texture t;
    t.name = name;
    t.width = w;
    t.height = h;
    t.rgba8.assign(size_t(w) * h * 4, 128);
    return t;
}

TEST(TexturePath, BufferWithoutDescriptorIndexingArrayWithIt) {
    const TextureCaps lp = lavapipe_caps(), gpu = indexing_caps();
    EXPECT_EQ(choose_texture_path(lp, true, TexturePathRequest::automatic), TexturePath::buffer);
    EXPECT_EQ(choose_texture_path(gpu, true, TexturePathRequest::automatic), TexturePath::array);
    EXPECT_EQ(choose_texture_path(gpu, true, TexturePathRequest::buffer), TexturePath::buffer);
    EXPECT_EQ(choose_texture_path(gpu, true, TexturePathRequest::array), TexturePath::array);
    // Either feature alone is not enough.
    for (int missing = 0; missing < 2; ++missing) {
        TextureCaps c = gpu;
        (missing ? c.runtime_descriptor_array : c.sampled_image_array_nonuniform) = false;
        EXPECT_EQ(choose_texture_path(c, true, TexturePathRequest::automatic), TexturePath::buffer);
        EXPECT_NE(texture_array_unavailable(c), "");
    }
    EXPECT_EQ(texture_array_unavailable(gpu), "");
    // A scene that samples no texture fetches none, whichever path.
    EXPECT_EQ(choose_texture_path(gpu, false, TexturePathRequest::automatic), TexturePath::none);
    EXPECT_EQ(choose_texture_path(lp, false, TexturePathRequest::buffer), TexturePath::none);
}

TEST(TexturePath, ArrayRequestedWithoutTheFeaturesIsAnError) {
    try {
        choose_texture_path(lavapipe_caps(), true, TexturePathRequest::array);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("runtimeDescriptorArray"), std::string::npos) << m;
        EXPECT_NE(m.find("shaderSampledImageArrayNonUniformIndexing"), std::string::npos) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << "one line";
    }
}

TEST(TexturePath, CapsComeFromTheDeviceFeatures) {
    vk::DeviceFeatures f;
    f.runtime_descriptor_array = true;
    f.sampled_image_array_nonuniform = false;
    f.max_sampled_images = 77;
    f.max_image_dimension_2d = 4096;
    f.max_storage_buffer_range = 1u << 27;
    const TextureCaps c = texture_caps(f);
    EXPECT_TRUE(c.runtime_descriptor_array);
    EXPECT_FALSE(c.sampled_image_array_nonuniform);
    EXPECT_EQ(c.max_sampled_images, 77u);
    EXPECT_EQ(c.max_image_dimension_2d, 4096u);
    EXPECT_EQ(c.max_storage_buffer_range, 1ull << 27);
    EXPECT_EQ(choose_texture_path(c, true, TexturePathRequest::automatic), TexturePath::buffer);
}

TEST(TexturePath, ParsesTheOption) {
    EXPECT_EQ(parse_texture_path("auto"), TexturePathRequest::automatic);
    EXPECT_EQ(parse_texture_path("buffer"), TexturePathRequest::buffer);
    EXPECT_EQ(parse_texture_path("array"), TexturePathRequest::array);
    EXPECT_THROW(parse_texture_path("atlas"), Error);
    EXPECT_THROW(parse_texture_path(""), Error);
}

TEST(TexturePath, TexelBudgetFollowsTheStorageRange) {
    EXPECT_EQ(texel_budget_bytes(128ull << 20), 96ull << 20); // lavapipe
    EXPECT_EQ(texel_budget_bytes(4ull << 30), 1ull << 30);    // NVIDIA: capped at 1 GiB
    EXPECT_EQ(texel_budget_bytes(512ull << 20), 384ull << 20);
    EXPECT_EQ(texel_budget_bytes(0), 96ull << 20);            // unknown range: lavapipe's
}

TEST(TexturePath, BufferPlanHalvesTheLargestAsPackSceneDoes) {
    Scene s = test::make_quad_scene();
    s.textures = {texture(64, 64, "a"), texture(32, 16, "b"), Texture{"broken", 8, 8, {}}, texture(64, 32, "c")};
    s.materials[0].base_color_tex.texture = 0;
    // 16384 + 2048 + 4 (broken: 1x1) + 8192 bytes; a 12 KiB budget needs a 64x64 -> 32x32 halving (4096),
    // then the 64x32 (now the largest, 8192) -> 32x16.
    const TexelBufferPlan p = plan_texel_buffer(s.textures, 12 * 1024);
    EXPECT_EQ(p.total_halvings, 2u);
    EXPECT_EQ(p.halvings, (std::vector<uint32_t>{1, 0, 0, 1}));
    EXPECT_EQ(p.bytes, 4096u + 2048u + 4u + 2048u);
    PackOptions o;
    o.texel_budget_bytes = 12 * 1024;
    const GpuSceneData d = pack_scene(s, build_scene_accel(s), Environment{}, o);
    EXPECT_EQ(d.texture_downscales, p.total_halvings);
    EXPECT_EQ(uint64_t(d.texels.size()) * 4, p.bytes);
    const uint32_t want[4][2] = {{32, 32}, {32, 16}, {1, 1}, {32, 16}};
    for (size_t i = 0; i < 4; ++i) {
        EXPECT_EQ(d.texture_infos[i].width, want[i][0]) << i;
        EXPECT_EQ(d.texture_infos[i].height, want[i][1]) << i;
    }
    // Without a budget problem nothing is halved; the texture-array path packs no texels.
    EXPECT_EQ(plan_texel_buffer(s.textures, 1u << 20).total_halvings, 0u);
    o.textures = false;
    EXPECT_EQ(pack_scene(s, build_scene_accel(s), Environment{}, o).texels.size(), 1u);
}

TEST(TexturePath, ArrayLimitsAreOneLineErrors) {
    const std::vector<Texture> three = {texture(4, 4), texture(8, 2), texture(2, 2)};
    TextureCaps c = indexing_caps();
    EXPECT_NO_THROW(check_texture_array_limits(c, three, 29));
    auto expect_error = [&](const TextureCaps& caps, const std::vector<Texture>& t, const char* names) {
        try {
            check_texture_array_limits(caps, t, 29);
            ADD_FAILURE() << "expected an error naming " << names;
        } catch (const Error& e) {
            const std::string m = e.what();
            EXPECT_NE(m.find(names), std::string::npos) << m;
            EXPECT_NE(m.find("--texture-path buffer"), std::string::npos) << m;
            EXPECT_EQ(m.find('\n'), std::string::npos) << m;
        }
    };
    TextureCaps few = c;
    few.max_sampled_images = 2;
    expect_error(few, three, "maxDescriptorSet");
    TextureCaps resources = c;
    resources.max_per_stage_resources = 31;
    expect_error(resources, three, "maxPerStageResources");
    TextureCaps allocations = c;
    allocations.max_memory_allocations = 130;
    expect_error(allocations, three, "maxMemoryAllocationCount");
    TextureCaps small = c;
    small.max_image_dimension_2d = 4;
    expect_error(small, three, "maxImageDimension2D");
}

TEST(TexturePath, PlanSaysWhatRunsAndItsMemory) {
    Scene s = test::make_quad_scene();
    s.textures = {texture(64, 64), texture(16, 16)};
    const TexturePlan a = plan_textures(indexing_caps(), s, true, TexturePathRequest::automatic);
    EXPECT_EQ(a.path, TexturePath::array);
    EXPECT_EQ(a.textures, 2u);
    EXPECT_EQ(a.bytes, (64u * 64u + 16u * 16u) * 4u);
    EXPECT_NE(describe(a).find("array"), std::string::npos);
    const TexturePlan b = plan_textures(lavapipe_caps(), s, true, TexturePathRequest::automatic);
    EXPECT_EQ(b.path, TexturePath::buffer);
    EXPECT_EQ(b.budget, 96ull << 20);
    EXPECT_EQ(b.bytes, a.bytes);
    EXPECT_NE(describe(b).find("runtimeDescriptorArray"), std::string::npos) << describe(b);
    EXPECT_EQ(plan_textures(lavapipe_caps(), s, false, TexturePathRequest::automatic).path, TexturePath::none);
}

// Ids decorated with Binding `binding` and DescriptorSet 0 in a SPIR-V module; and its capabilities.
struct SpirvFacts {
    bool declares_binding = false;
    bool runtime_descriptor_array = false; // OpCapability RuntimeDescriptorArray (5302)
};
SpirvFacts spirv_facts(std::span<const uint32_t> words, uint32_t binding) {
    SpirvFacts f;
    std::vector<uint32_t> bound, set0;
    for (size_t i = 5; i < words.size();) {
        const uint32_t op = words[i] & 0xFFFFu, count = words[i] >> 16;
        if (count == 0 || i + count > words.size()) break;
        if (op == 17 && count >= 2 && words[i + 1] == 5302) f.runtime_descriptor_array = true;
        if (op == 71 && count >= 4) { // OpDecorate id decoration literal
            if (words[i + 2] == 33 && words[i + 3] == binding) bound.push_back(words[i + 1]);
            if (words[i + 2] == 34 && words[i + 3] == 0) set0.push_back(words[i + 1]);
        }
        i += count;
    }
    for (uint32_t id : bound)
        if (std::find(set0.begin(), set0.end(), id) != set0.end()) f.declares_binding = true;
    return f;
}

TEST(ShaderVariants, EveryPassSamplingTexturesHasItsArrayVariant) {
    int passes = 0, variants = 0;
    for (std::string_view name : shaders::names()) {
        if (name.substr(0, 7) != "passes/" || name.find('#') != std::string_view::npos) continue;
        ++passes;
        const SpirvFacts plain = spirv_facts(shaders::find(name), NB_BIND_TEXELS);
        // The plain pass runs on lavapipe: never a descriptor-indexing capability.
        EXPECT_FALSE(plain.runtime_descriptor_array) << name;
        const std::string v = shaders::variant(name, "texture_array");
        if (plain.declares_binding) {
            EXPECT_NE(v, std::string(name)) << name << " samples textures, no array variant";
        }
        if (v == name) continue;
        ++variants;
        const SpirvFacts arr = spirv_facts(shaders::find(v), NB_BIND_TEXELS);
        EXPECT_TRUE(arr.runtime_descriptor_array) << v;
    }
    EXPECT_GE(passes, 10);
    EXPECT_GE(variants, 4); // traverse, shade, shadow and the neural traversals at least
    EXPECT_EQ(shaders::variant("passes/camera_rays.comp", "texture_array"), "passes/camera_rays.comp");
    EXPECT_EQ(shaders::variant("passes/shade.comp", "texture_array"), "passes/shade.comp#texture_array");
}

} // namespace
} // namespace nbvh::render
