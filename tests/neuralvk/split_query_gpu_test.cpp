// The split query pass (a gather pass, then an MLP pass reading the features it stored; shared/
// neural_gpu.h NB_SPLIT_*) against the fused pass in a hybrid render on a GPU with fp32 cooperative
// matrices (label `gpu`; lavapipe has none, so on CI the test skips). Both passes compute the same
// features (the same paired gather, the same fp16 rounding) and run the same MLP code on them, so the
// images must be the same bytes and the queries the same, also when a round holds more pairs than the
// features buffer (the fused pass takes the rest: a buffer of 64 pairs here). A scene built in code (a sphere and a box, neural, on a classical
// ground), a small CPU-trained model (~3 s), 96x64, 4 samples, 3 path segments (camera, secondary and
// shadow rays through the neural assets). A wrong pair offset or feature order changes the image (a
// hit answered with another pair's features).
#include "assets/procedural_mesh.h"
#include "engine/bvh/scene_accel.h"
#include "engine/core/error.h"
#include "engine/neural/asset_table.h"
#include "engine/render/neural_grid_pack.h"
#include "engine/render/neural_model_gpu.h"
#include "engine/render/neural_stage.h"
#include "engine/render/wavefront.h"
#include "engine/scene/environment.h"
#include "trainer/model_export.h"
#include "trainer/trainer.h"

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cstdio>
#include <memory>

using namespace nbvh;
using namespace nbvh::render;
using namespace nbvh::assets;

namespace {

Scene make_scene() {
    Scene s;
    Material red, ground;
    red.name = "red";
    red.base_color = glm::vec4(0.8f, 0.2f, 0.1f, 1.0f);
    red.roughness = 0.4f;
    ground.name = "ground";
    ground.base_color = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
    ground.roughness = 0.9f;
    s.materials = {red, ground};
    s.meshes.push_back(make_sphere("ball", 0.5f, 32, 16, 0));
    s.meshes.push_back(make_box("brick", glm::vec3(0.4f, 0.2f, 0.3f), 0));
    s.meshes.push_back(make_ground("ground", 6.0f, 1));
    const char* names[] = {"ball", "brick", "ground"};
    const glm::vec3 at[] = {{-0.4f, 0.5f, 0.0f}, {0.5f, 0.3f, 0.2f}, {0.0f, 0.0f, 0.0f}};
    for (uint32_t m = 0; m < 3; ++m) {
        Instance i;
        i.name = names[m];
        i.mesh = m;
        i.object_to_world = glm::translate(glm::mat4(1.0f), at[m]);
        i.neural = m < 2;
        s.instances.push_back(i);
    }
    s.camera.eye = glm::vec3(0.1f, 1.2f, 2.4f);
    s.camera.target = glm::vec3(0.0f, 0.35f, 0.0f);
    s.camera.yfov = 0.8f;
    s.has_camera = true;
    return s;
}

struct Frame {
    std::vector<float> pixels;
    RenderStats stats;
    std::string path;
    uint32_t query_passes = 0;
};

} // namespace

TEST(SplitQuery, SameImageAsTheFusedPass) {
    vk::ContextOptions co;
    co.device = vk::DeviceChoice::gpu;
    co.validation = true;
    std::unique_ptr<vk::Context> ctx;
    try {
        ctx = std::make_unique<vk::Context>(co);
    } catch (const Error& e) {
        GTEST_SKIP() << "no Vulkan GPU: " << e.what();
    }
    const NeuralKernelChoice kernel = choose_neural_kernel(ctx->features(), NeuralPath::automatic);
    if (kernel.path != NeuralPath::coopmat || !kernel.fp32_accumulate)
        GTEST_SKIP() << "no fp32 cooperative-matrix kernel on this device: the split pass does not run";

    Scene train_scene = make_scene();
    split_neural_meshes(train_scene);
    const TrainingAsset asset = make_training_asset(train_scene, neural_meshes(train_scene));
    TrainOptions opt = default_train_options(BackendChoice::cpu);
    opt.steps = 200;
    opt.batch_size = 2048;
    opt.target_nodes = 120;
    // 2^18 (the default): levels 0-3 are dense with power-of-two sizes, so the gather pass reads the first
    // batch of levels through the y-pair table (shared/hashgrid.h) and the fused pass the plain entries.
    opt.network.log2_hash_size = 18;
    auto backend = make_backend(BackendChoice::cpu, asset, opt);
    const NeuralModel model =
        make_neural_model(asset, train_asset(asset, opt, *backend), opt, "split_query_test", 0);
    ASSERT_EQ(ypair_level_count(model.levels), 4u); // the gather's first batch of 4 levels is y-paired

    const Scene scene = make_scene();
    const SceneAccel accel = build_scene_accel(scene);
    auto render = [&](bool split, uint32_t limit, uint32_t min_pairs) {
        RenderOptions o;
        o.width = 96;
        o.height = 64;
        o.spp = 4;
        o.max_depth = 3;
        o.seed = 5;
        o.neural.model = &model;
        o.neural.split_query = split;
        o.neural.split_chunk_limit = limit;
        o.neural.split_min_pairs = min_pairs;
        WavefrontRenderer r(*ctx, scene, accel, default_sky(), scene.camera, o);
        const RenderResult res = r.render();
        return Frame{res.image.data, res.stats, res.stats.neural_path, r.neural_query_passes()};
    };
    const Frame fused = render(false, 0, 0);
    const Frame one = render(true, 0, 0);
    // 96 x 64 x 4 paths, 2 leaves per round: 49,152 pairs per half, 64 of them (one workgroup) in the
    // split pass, the rest of a round's pairs through the fused pass (NB_QUERY_MODE_OVERFLOW).
    const Frame part = render(true, 64, 0);
    // Every round below split_min_pairs: the fused pass takes each whole (its overflow dispatch from pair
    // 0); then the mean round as the bound: the larger rounds split, the smaller ones fused.
    const Frame small = render(true, 0, 1u << 30);
    const uint32_t mean_round =
        uint32_t(fused.stats.neural_queries / std::max<uint64_t>(fused.stats.neural_rounds, 1));
    const Frame mixed = render(true, 0, mean_round);
    std::printf("fused: %s, %llu queries; split: %s, %u and %u query passes per round\n", fused.path.c_str(),
                (unsigned long long)fused.stats.neural_queries, one.path.c_str(), one.query_passes, part.query_passes);
    EXPECT_EQ(fused.query_passes, 1u);
    EXPECT_EQ(one.query_passes, 2u);
    EXPECT_EQ(part.query_passes, 3u);
    EXPECT_EQ(small.query_passes, 3u);
    EXPECT_EQ(mixed.query_passes, 3u);
    EXPECT_NE(one.path.find("split"), std::string::npos);
    EXPECT_GT(fused.stats.neural_queries, 1000u);
    // More queries than 64 per round on average: some round held more pairs than the split pass took,
    // so the overflow's fused dispatch had work.
    EXPECT_GT(fused.stats.neural_queries, 64u * fused.stats.neural_rounds);
    for (const Frame* f : {&one, &part, &small, &mixed}) {
        EXPECT_EQ(f->stats.neural_queries, fused.stats.neural_queries);
        EXPECT_EQ(f->stats.rays_shadow, fused.stats.rays_shadow);
        EXPECT_EQ(f->pixels, fused.pixels);
        EXPECT_EQ(f->stats.nonfinite_pixels, 0u);
    }
    EXPECT_EQ(ctx->validation_message_count(), 0);
}
