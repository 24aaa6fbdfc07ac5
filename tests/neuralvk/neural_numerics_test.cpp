// Numerics of the neural query around the network, on lavapipe: origins inside leaves and on leaf
// faces (reversed queries), rays parallel to leaf faces, flat leaves (zero extent on an axis), leaves
// of a flat asset (zero-extent encoding box axis). For each case the leaf interval comes from the shared
// header (shaders/shared/neural_gpu.h nb_neural_leaf_interval) and the GPU result must be finite and
// match the CPU reference (same bounds as the cross-check test).
#include "engine/render/neural_model_gpu.h"
#include "engine/vk/context.h"
#include "tests/neuralvk/neural_test_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace nbvh;
using namespace nbvh::render;

namespace {

struct Case {
    std::string name;
    glm::vec3 org, dir, lo, hi; // leaf box
    bool expect_hit_interval = true;
    bool expect_reversed = false;
};

void run_cases(const test::TestModel& tm, const std::vector<Case>& cases) {
    vk::ContextOptions o;
    o.device = vk::DeviceChoice::cpu;
    o.validation = true;
    vk::Context ctx(o);
    NeuralModelGpu gpu(ctx, tm.model);
    NeuralEvaluator eval(ctx, gpu, choose_neural_kernel(ctx.features(), NeuralPath::scalar));
    std::vector<GpuNeuralQuery> qs;
    std::vector<const Case*> kept;
    for (const Case& c : cases) {
        GpuNeuralQuery q;
        q.origin = c.org;
        q.dir = glm::normalize(c.dir);
        const bool hit = nb_neural_leaf_interval(q.origin, nb_safe_inv_dir(q.dir), c.lo, c.hi, q.t_entry, q.t_exit);
        EXPECT_EQ(hit, c.expect_hit_interval) << c.name;
        if (!hit) continue;
        EXPECT_TRUE(std::isfinite(q.t_entry) && std::isfinite(q.t_exit)) << c.name;
        EXPECT_LE(q.t_entry, q.t_exit) << c.name;
        EXPECT_EQ(nb_query_reversed(q.t_entry), c.expect_reversed) << c.name << " t_entry " << q.t_entry;
        // The encoded points stay in the valid range (inside the dilated encoding box).
        glm::vec3 p[3];
        nb_segment_points(tm.box, q.origin, q.dir, q.t_entry, q.t_exit, p[0], p[1], p[2]);
        for (const glm::vec3& e : p)
            for (int k = 0; k < 3; ++k) {
                EXPECT_GE(e[k], -1e-3f) << c.name;
                EXPECT_LE(e[k], 1.001f) << c.name;
            }
        qs.push_back(q);
        kept.push_back(&c);
    }
    const std::vector<GpuNeuralHit> hits = eval.evaluate(qs);
    for (size_t i = 0; i < qs.size(); ++i) {
        const neural::Outputs y = test::reference_outputs(tm, qs[i]);
        const GpuNeuralHit& h = hits[i];
        const std::string& name = kept[i]->name;
        for (float v : {h.visibility, h.depth, h.t, h.normal.x, h.normal.y, h.normal.z, h.albedo.x})
            EXPECT_TRUE(std::isfinite(v)) << name;
        EXPECT_NEAR(glm::length(h.normal), 1.0f, 1e-3f) << name;
        EXPECT_NEAR(h.visibility, y[0], 2e-3f) << name;
        EXPECT_NEAR(h.depth, y[1], 2e-3f) << name;
        float t_ref;
        nb_decode_depth(tm.box, y[1], qs[i].t_entry, qs[i].t_exit, glm::length(qs[i].dir), t_ref);
        const float len = qs[i].t_exit - qs[i].t_entry + tm.box.depth_pad / glm::length(qs[i].dir);
        EXPECT_NEAR(h.t, t_ref, 2e-3f * len) << name;
        // A reversed query never accepts a hit behind (or at) the origin: no self-hit of a secondary
        // ray leaving a neural surface inside this leaf.
        if (nb_query_reversed(qs[i].t_entry) && (h.flags & NB_NEURAL_ACCEPTED)) {
            EXPECT_GT(h.t, NB_DEPTH_EPSILON * (qs[i].t_exit - qs[i].t_entry)) << name;
        }
        if (qs[i].t_exit < 0.0f) { EXPECT_FALSE(h.flags & NB_NEURAL_ACCEPTED) << name; }
    }
    EXPECT_EQ(ctx.validation_message_count(), 0);
}

} // namespace

TEST(NeuralNumerics, InsideOnFaceParallelFlat) {
    const glm::vec3 alo(-1.0f), ahi(1.0f);
    const test::TestModel tm = test::make_test_model(3, alo, ahi);
    const glm::vec3 lo(-0.5f, -0.25f, 0.0f), hi(0.5f, 0.25f, 0.75f);
    std::vector<Case> cs = {
        {"outside, diagonal", {-1, -1, -1}, {1, 0.9f, 1.1f}, lo, hi, true, false},
        {"origin at the centre", {0, 0, 0.375f}, {0.3f, -0.2f, 1}, lo, hi, true, true},
        {"origin on the -x face, going in", {-0.5f, 0, 0.3f}, {1, 0.1f, 0.2f}, lo, hi, true, true},
        {"origin on the +x face, going out", {0.5f, 0, 0.3f}, {1, 0.1f, 0.2f}, lo, hi, true, true},
        {"origin on a corner", {0.5f, 0.25f, 0.75f}, {-1, -1, -1}, lo, hi, true, true},
        {"parallel to the z faces, inside the slab", {-2, 0.1f, 0.3f}, {1, 0, 0}, lo, hi, true, false},
        {"parallel, in the plane of the z = 0 face", {-2, 0.1f, 0.0f}, {1, 0, 0}, lo, hi, true, false},
        {"parallel, outside the slab", {-2, 0.1f, 0.8f}, {1, 0, 0}, lo, hi, false, false},
        {"axis-aligned through the centre", {0, 0, -3}, {0, 0, 1}, lo, hi, true, false},
        {"flat leaf (z extent 0), crossing", {0.1f, 0.05f, -1}, {0.1f, 0.0f, 1}, {-0.5f, -0.25f, 0.2f},
         {0.5f, 0.25f, 0.2f}, true, false},
        {"flat leaf, ray in its plane", {-2, 0.0f, 0.2f}, {1, 0.05f, 0}, {-0.5f, -0.25f, 0.2f},
         {0.5f, 0.25f, 0.2f}, true, false},
        // On a flat leaf the interval is [0, ~0]: a zero-length forward query (the renderer culls
        // leaves whose exit is not beyond its tmin, so such a ray never queries its own surface).
        {"flat leaf, origin on it", {0.0f, 0.0f, 0.2f}, {0.2f, 0.1f, 1}, {-0.5f, -0.25f, 0.2f},
         {0.5f, 0.25f, 0.2f}, true, false},
        {"grazing an edge", {-2, 0.25f, 0.75f}, {1, 0, 0}, lo, hi, true, false},
        // Entirely behind: t_exit < 0, "reversed", and the depth decode can never accept it.
        {"leaf behind the origin", {0, 0, 3}, {0, 0, 1}, lo, hi, true, true},
    };
    run_cases(tm, cs);
}

TEST(NeuralNumerics, FlatAssetEncodingBox) {
    // A plane asset: the encoding box has zero y extent and is padded by nb_make_encoding_box.
    const glm::vec3 alo(-1.0f, 0.0f, -1.0f), ahi(1.0f, 0.0f, 1.0f);
    const test::TestModel tm = test::make_test_model(5, alo, ahi);
    EXPECT_GT(tm.box.extent.y, 0.0f);
    std::vector<Case> cs = {
        {"down onto the plane", {0.2f, 1, 0.3f}, {0.1f, -1, 0.05f}, alo, ahi, true, false},
        {"in the plane", {-3, 0, 0.1f}, {1, 0, 0.02f}, alo, ahi, true, false},
        {"leaving the plane upwards", {0.1f, 0, 0.1f}, {0.3f, 1, 0.2f}, alo, ahi, true, false},
    };
    run_cases(tm, cs);
}
