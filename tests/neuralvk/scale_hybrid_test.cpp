// Any scale, anywhere (issue 12), hybrid renders end to end on lavapipe (validation on): a small scene
// built in code (a neural sphere and a neural box on a classical 4 m ground), one CPU-trained model (600
// steps, hash 2^14, ~300 nodes: a few seconds), rendered hybrid with the scene scaled by 1e-1, 1e-2, 1e-4
// and 1e4 about the origin and at 1e4 moved 3000 km away, framed by
// the automatic camera; each render is finite and matches the 1 m hybrid render of the same model.
//
// Bound: LDR-FLIP (at the 1 m image's auto exposure) below a tenth of the noise floor (the 1 m hybrid
// render with another seed). Why: the model answers in each asset's normalised space, which the instance
// transforms map to any scale, so the scaled renders ask the network the same queries up to float
// rounding; with shared random numbers nearly every path is the same, and the network's outputs being
// smooth in its inputs, only rays whose visibility is within rounding of the threshold (a few silhouette
// pixels) differ (measured: <= 0.001 at every scale from 1e-6 to 1e4). A scale-dependent constant in the
// neural traversal or decode (a leaf-entry epsilon, the resume distance, the offset of rays leaving a
// neural surface, a depth pad in the wrong units) makes secondary rays re-hit the surface or hits move
// inside their leaves at one scale. The depth decode had one: the object-space depth pad was applied in
// ray-parameter units, 0.0142 / 0.0197 / 0.0129 at 1e-1 / 1e-2 / 1e-4 (queries +17 % at 1e-1) before
// shared/neural_query.h nb_decode_depth took the direction's length.
#include "assets/procedural_mesh.h"
#include "engine/neural/asset_table.h"
#include "engine/render/wavefront.h"
#include "engine/scene/environment.h"
#include "tests/render/scaled_scene.h"
#include "trainer/model_export.h"
#include "trainer/trainer.h"

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <cstdio>

using namespace nbvh;
using namespace nbvh::render;

namespace {

constexpr double FRACTION_OF_FLOOR = 0.1;

Material material(const char* name, glm::vec3 base, float roughness) {
    Material m;
    m.name = name;
    m.base_color = glm::vec4(base, 1.0f);
    m.roughness = roughness;
    return m;
}

Scene make_scene() {
    Scene s;
    s.materials = {material("clay", {0.8f, 0.35f, 0.2f}, 0.5f), material("paint", {0.1f, 0.3f, 0.8f}, 0.4f),
                   material("ground", {0.5f, 0.5f, 0.5f}, 0.9f)};
    s.meshes = {assets::make_sphere("ball", 0.5f, 32, 16, 0), assets::make_box("brick", glm::vec3(0.3f, 0.2f, 0.25f), 1),
                assets::make_ground("ground", 4.0f, 2)};
    auto add = [&](const char* name, uint32_t mesh, const glm::mat4& m, bool neural) {
        Instance i;
        i.name = name;
        i.mesh = mesh;
        i.object_to_world = m;
        i.neural = neural;
        s.instances.push_back(i);
    };
    add("ball", 0, glm::translate(glm::mat4(1.0f), {-0.4f, 0.5f, 0.0f}), true);
    add("brick", 1,
        glm::translate(glm::mat4(1.0f), {0.55f, 0.2f, 0.2f}) *
            glm::rotate(glm::mat4(1.0f), glm::radians(30.0f), glm::vec3(0, 1, 0)),
        true);
    add("ground", 2, glm::mat4(1.0f), false);
    return s; // no glTF camera: the automatic one frames each scale
}

const NeuralModel& trained_model() {
    static const NeuralModel* model = [] {
        Scene train = make_scene();
        split_neural_meshes(train);
        const TrainingAsset asset = make_training_asset(train, neural_meshes(train));
        TrainOptions opt = default_train_options(BackendChoice::cpu);
        opt.steps = 600;
        opt.batch_size = 2048;
        opt.target_nodes = 300;
        opt.network.log2_hash_size = 14;
        opt.threads = 2;
        auto backend = make_backend(BackendChoice::cpu, asset, opt);
        const TrainResult r = train_asset(asset, opt, *backend);
        return new NeuralModel(make_neural_model(asset, r, opt, "scale_hybrid_test", 0));
    }();
    return *model;
}

using test::ScaledRender;

ScaledRender render_hybrid(const Scene& scene, uint32_t seed) {
    RenderOptions o;
    o.spp = 4;
    o.max_depth = 3;
    o.seed = seed;
    o.neural.path = NeuralPath::scalar;
    o.neural.model = &trained_model();
    ScaledRender r = test::render_scaled(scene, default_sky(), o);
    EXPECT_GT(r.stats.neural_queries, 0u) << "the render must be hybrid";
    return r;
}

} // namespace

TEST(ScaleHybrid, EveryScaleMatchesOneMetre) {
    Scene base = make_scene();
    bind_model_to_scene(base, trained_model(), "scale.nbvh");
    const test::ScaleCase cases[] = {{"1e-1 (40 cm) at the origin", 1.0e-1f, glm::vec3(0.0f)},
                                     {"1e-2 (4 cm) at the origin", 1.0e-2f, glm::vec3(0.0f)},
                                     {"1e-4 (0.4 mm) at the origin", 1.0e-4f, glm::vec3(0.0f)},
                                     {"1e4 (40 km) at the origin", 1.0e4f, glm::vec3(0.0f)},
                                     {"1e4 (40 km), 3000 km away", 1.0e4f, glm::vec3(2.0e6f, 0.0f, -2.2e6f)}};
    test::expect_every_scale_matches(base, cases, 3, FRACTION_OF_FLOOR, render_hybrid,
                                     [](const ScaledRender& ref, const ScaledRender& r) {
                                         ASSERT_GT(ref.stats.neural_queries, 0u);
                                         EXPECT_GT(r.stats.neural_queries, 0u);
                                         std::printf("  neural queries %llu vs %llu at 1 m\n",
                                                     (unsigned long long)r.stats.neural_queries,
                                                     (unsigned long long)ref.stats.neural_queries);
                                     });
}
