// Both texture paths (engine/render/texture_path.h) on a GPU with descriptor indexing: the texel buffer
// and the sampled-image array compute the same bilinear footprint and weights in the shader
// (nb_bilinear_footprint in shaders/lib/textures.glsl; the array path reads its four texels with
// texelFetch), so they must give the same images up to float rounding. Label gpu: skips without a Vulkan
// GPU or without descriptor indexing (lavapipe), so CI passes; it runs on the GPU machine
// (results/render/README.md says how).
//
// Bounds (why):
// - Direct lookups (max depth 1: the emissive wall seen directly, radiance = E * srgb_to_linear(filtered
//   texel)): the same texels and weights; the only freedom is how each implementation turns an 8-bit
//   value into a float (exact c/255 in unpackUnorm4x8, the UNORM conversion's rounding in texelFetch:
//   a few ulps) -> 1e-5 relative to the value, plus 1e-7. Measured on the H100: max 0 at 5 decimals,
//   mean 4e-9. With the sampler's own bilinear filter (before: 8-bit weights, and a REPEAT seam row it
//   resolved differently) the same test measured 0.16 against the then bound E * 2.3 * (2 D + 0.5) / 256
//   = 0.045, D the largest neighbouring-texel difference. A half-texel shift, nearest filtering, a
//   flipped v, CLAMP instead of REPEAT or a double sRGB decode break it by orders of magnitude.
// - Path-traced images (same seed, so the same random numbers): besides the lookups above, a sample
//   differs only where a random decision (lobe choice from the base colour, alpha cutoff, Russian
//   roulette) sits on a threshold that the 2^-8 difference moves: rare. Required: HDR-FLIP between the
//   paths at most a quarter of the noise floor (the buffer path against itself with another seed at the
//   same spp), so no texture difference is visible above the Monte Carlo noise. Negative control: the
//   array path with the base-colour texture flipped vertically must exceed that bound.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "engine/bvh/scene_accel.h"
#include "engine/core/error.h"
#include "engine/core/flip.h"
#include "engine/render/wavefront.h"
#include "engine/scene/environment.h"
#include "engine/vk/context.h"
#include "tests/render/test_scenes.h"

namespace nbvh::render {
namespace {

struct Gpu {
    std::unique_ptr<vk::Context> ctx;
    std::string skip; // why the test cannot run here
};

Gpu open_gpu() {
    Gpu g;
    vk::ContextOptions o;
    o.device = vk::DeviceChoice::gpu;
    o.validation = true;
    try {
        g.ctx = std::make_unique<vk::Context>(o);
    } catch (const Error& e) {
        g.skip = std::string("no Vulkan GPU: ") + e.what();
        return g;
    }
    const std::string why = texture_array_unavailable(texture_caps(g.ctx->features()));
    if (!why.empty()) g.skip = "no texture-array path: " + why;
    return g;
}

RenderResult render(const vk::Context& ctx, const Scene& scene, TexturePathRequest path, uint32_t spp,
                    uint32_t max_depth, uint32_t seed, uint32_t width, uint32_t height) {
    const SceneAccel accel = build_scene_accel(scene);
    const Environment env = constant_environment(glm::vec3(0.6f, 0.7f, 0.9f));
    RenderOptions opt;
    opt.width = width;
    opt.height = height;
    opt.spp = spp;
    opt.max_depth = max_depth;
    opt.seed = seed;
    opt.texture_path = path;
    WavefrontRenderer r(ctx, scene, accel, env, scene.camera, opt);
    RenderResult res = r.render();
    const char* want = path == TexturePathRequest::array ? "array" : "buffer";
    EXPECT_EQ(res.stats.texture_path, want);
    EXPECT_EQ(res.stats.texture_count, uint32_t(scene.textures.size()));
    EXPECT_GT(res.stats.texture_bytes, 0u);
    EXPECT_EQ(res.stats.texture_halvings, 0u);
    EXPECT_EQ(res.stats.nonfinite_pixels, 0u);
    return res;
}

// Largest difference of horizontally or vertically neighbouring texels (REPEAT wrap), in [0, 1].
float largest_neighbour_step(const Texture& t) {
    int step = 0;
    for (uint32_t y = 0; y < t.height; ++y)
        for (uint32_t x = 0; x < t.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const int v = t.rgba8[(size_t(y) * t.width + x) * 4 + c];
                const int r = t.rgba8[(size_t(y) * t.width + (x + 1) % t.width) * 4 + c];
                const int d = t.rgba8[(size_t((y + 1) % t.height) * t.width + x) * 4 + c];
                step = std::max({step, std::abs(v - r), std::abs(v - d)});
            }
    return float(step) / 255.0f;
}

TEST(TextureArrayGpu, DirectLookupsAgreeWithinTheFilterPrecision) {
    Gpu g = open_gpu();
    if (!g.skip.empty()) GTEST_SKIP() << g.skip;
    Scene scene = test::make_textured_scene();
    scene.instances.pop_back(); // the alpha-masked quad: its cutoff crossings are the path-traced test's
    const uint32_t w = 320, h = 200;
    const RenderResult b = render(*g.ctx, scene, TexturePathRequest::buffer, 4, 1, 3, w, h);
    const RenderResult a = render(*g.ctx, scene, TexturePathRequest::array, 4, 1, 3, w, h);
    const float step = largest_neighbour_step(scene.textures[test::TEXTURED_SCENE_EMISSIVE_TEXTURE]);
    const float bound = 1e-5f * test::TEXTURED_SCENE_EMISSIVE_SCALE + 1e-7f; // radiance <= E
    float max_diff = 0.0f;
    double sum_diff = 0.0;
    size_t emissive = 0, differing = 0, over = 0, worst = 0;
    int worst_c = 0;
    uint32_t x0 = w, y0 = h, x1 = 0, y1 = 0; // box of the values over the bound
    for (size_t i = 0; i < b.image.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) {
            const float vb = b.image.data[i * 4 + c], va = a.image.data[i * 4 + c];
            const float d = std::fabs(vb - va);
            if (d > max_diff) worst = i, worst_c = c;
            if (d > bound) {
                ++over;
                x0 = std::min(x0, uint32_t(i % w)), x1 = std::max(x1, uint32_t(i % w));
                y0 = std::min(y0, uint32_t(i / w)), y1 = std::max(y1, uint32_t(i / w));
            }
            max_diff = std::max(max_diff, d);
            sum_diff += d;
            differing += d > 0.0f;
            if (c == 0 && vb > 0.7f) ++emissive; // the sky is 0.6 red; the wall's red ramp reaches 2
        }
    std::printf("direct lookups, %ux%u: max |buffer - array| %.3g (bound %.3g, neighbour step %.3f), mean %.3g, "
                "%zu of %zu values differ; %zu bright emissive pixels; texture bytes buffer %llu, array %llu\n",
                w, h, max_diff, bound, step, sum_diff / double(b.image.pixel_count() * 3), differing,
                b.image.pixel_count() * 3, emissive, (unsigned long long)b.stats.texture_bytes,
                (unsigned long long)a.stats.texture_bytes);
    EXPECT_GT(emissive, b.image.pixel_count() / 50) << "the emissive wall must be in view";
    EXPECT_LE(max_diff, bound) << "worst at pixel (" << worst % w << ", " << worst / w << ") channel " << worst_c
                               << ": buffer " << b.image.data[worst * 4 + worst_c] << ", array "
                               << a.image.data[worst * 4 + worst_c] << "; " << over << " values over the bound in x "
                               << x0 << ".." << x1 << ", y " << y0 << ".." << y1;
    if (g.ctx->validation_enabled()) {
        EXPECT_EQ(g.ctx->validation_message_count(), 0);
    }
}

TEST(TextureArrayGpu, PathTracedImagesAgreeBelowTheNoiseFloor) {
    Gpu g = open_gpu();
    if (!g.skip.empty()) GTEST_SKIP() << g.skip;
    const Scene scene = test::make_textured_scene();
    const uint32_t w = 320, h = 240, spp = 32, depth = 5;
    const RenderResult b1 = render(*g.ctx, scene, TexturePathRequest::buffer, spp, depth, 1, w, h);
    const RenderResult a1 = render(*g.ctx, scene, TexturePathRequest::array, spp, depth, 1, w, h);
    const RenderResult b2 = render(*g.ctx, scene, TexturePathRequest::buffer, spp, depth, 2, w, h);
    Scene flipped = scene;
    Texture& base = flipped.textures[0];
    for (uint32_t y = 0; y < base.height / 2; ++y)
        for (uint32_t x = 0; x < base.width * 4; ++x)
            std::swap(base.rgba8[size_t(y) * base.width * 4 + x], base.rgba8[size_t(base.height - 1 - y) * base.width * 4 + x]);
    const RenderResult af = render(*g.ctx, flipped, TexturePathRequest::array, spp, depth, 1, w, h);
    const float paths = flip_hdr(b1.image, a1.image).mean;
    const float floor = flip_hdr(b1.image, b2.image).mean;
    const float control = flip_hdr(b1.image, af.image).mean;
    const float bound = 0.25f * floor;
    std::printf("path traced %ux%u, %u spp, depth %u: HDR-FLIP buffer vs array (same seed) %.5f, noise floor "
                "(buffer, seeds 1 vs 2) %.5f, bound %.5f; control (array, base colour flipped) %.5f; GPU ms buffer "
                "%.2f, array %.2f\n", w, h, spp, depth, paths, floor, bound, control, b1.stats.gpu_ms,
                a1.stats.gpu_ms);
    EXPECT_GT(floor, 0.0f);
    EXPECT_LE(paths, bound);
    EXPECT_GT(control, bound) << "the comparison must see a texture error";
    if (g.ctx->validation_enabled()) {
        EXPECT_EQ(g.ctx->validation_message_count(), 0);
    }
}

} // namespace
} // namespace nbvh::render
