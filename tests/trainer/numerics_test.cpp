// Numerics of training on hard assets: flat (zero extent on an axis), tiny (1e-3) and huge (1e5)
// scale, far from the origin; rays parallel to leaf faces, origins inside leaves and on faces.
// Nothing may produce NaN/Inf: network inputs, ground truth, losses, gradients (steps are never
// skipped) and weights.
#include <gtest/gtest.h>

#include <cmath>

#include "shaders/shared/neural_query.h"
#include "shaders/shared/scene_gpu.h"
#include "engine/neural/shared/training_loss.h"
#include "tests/trainer/trainer_test_scenes.h"
#include "trainer/cpu/cpu_backend.h"
#include "trainer/ground_truth.h"
#include "trainer/trainer.h"

using namespace nbvh;

namespace {

bool finite3(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

struct Case {
    const char* name;
    Mesh mesh;
};

std::vector<Case> hard_cases() {
    std::vector<Case> c;
    c.push_back({"flat", test::height_field(8, 0.0f, 1.0f, glm::vec3(0.0f))});
    c.push_back({"tiny_1e-3", test::height_field(8, 0.2f, 1e-3f, glm::vec3(0.0f))});
    c.push_back({"huge_1e5", test::height_field(8, 0.2f, 1e5f, glm::vec3(0.0f))});
    c.push_back({"far_from_origin", test::height_field(8, 0.2f, 0.4f, glm::vec3(1e4f, -2e4f, 17.0f))});
    c.push_back({"flat_far_tiny", test::height_field(8, 0.0f, 1e-3f, glm::vec3(100.0f, 50.0f, -30.0f))});
    c.push_back({"cube", test::cube(1.0f)});
    return c;
}

// Encoded inputs, ground truth and segment of drawn training samples stay finite and in range.
void check_samples(const TrainingAsset& asset, const TrainingCut& cut) {
    const TrainingCut* cuts[1] = {&cut};
    uint64_t draws = 0;
    // Points are computed in object space: far from the origin their rounding (a few ulps of the
    // largest coordinate) is a visible fraction of a small asset's extent. That is the asset's own
    // precision (its vertices are quantised the same way), so the range check allows it.
    const glm::vec3 c = asset.encoding.center, e = asset.encoding.extent;
    const float max_coord = std::max({std::abs(c.x), std::abs(c.y), std::abs(c.z)}) + std::max({e.x, e.y, e.z});
    const float slack = 1e-3f + 8.0f * max_coord * 1.2e-7f / std::min({e.x, e.y, e.z});
    for (int i = 0; i < 3000; ++i) {
        const TrainingSample s = draw_training_sample(asset, cuts, {3, 4, uint32_t(i)}, nullptr, draws);
        ASSERT_GE(s.leaf, 0);
        ASSERT_TRUE(finite3(s.origin) && finite3(s.dir) && std::isfinite(s.length));
        vec3 p[3];
        nb_segment_points(asset.encoding, s.origin, s.dir, 0.0f, s.length, p[0], p[1], p[2]);
        for (const vec3& q : p) {
            ASSERT_TRUE(finite3(q));
            for (int a = 0; a < 3; ++a) {
                ASSERT_GE(q[a], -slack);
                ASSERT_LE(q[a], 1.0f + slack);
            }
        }
        const GroundTruth gt = trace_ground_truth(asset, s.origin, s.dir, 0.0f, s.length, SampleSlot{});
        ASSERT_TRUE(std::isfinite(gt.depth) && gt.depth >= 0.0f && gt.depth <= 1.0f);
        ASSERT_TRUE(finite3(gt.normal) && finite3(gt.albedo));
        if (gt.hit) {
            ASSERT_NEAR(glm::length(gt.normal), 1.0f, 1e-3f);
        }
    }
}

} // namespace

TEST(TrainerNumerics, HardAssetsTrainWithoutNonFiniteValues) {
    for (Case& c : hard_cases()) {
        SCOPED_TRACE(c.name);
        const Scene scene = test::scene_of(std::move(c.mesh));
        const TrainingAsset asset = make_training_asset(scene, 0);
        for (const Aabb& b : asset.node_boxes) {
            ASSERT_TRUE(finite3(b.lo) && finite3(b.hi));
            const glm::vec3 e = b.hi - b.lo;
            ASSERT_GT(std::min({e.x, e.y, e.z}), 0.0f); // thin boxes are padded
        }
        ASSERT_TRUE(finite3(asset.encoding.extent));
        ASSERT_GT(std::min({asset.encoding.extent.x, asset.encoding.extent.y, asset.encoding.extent.z}), 0.0f);

        TrainingCut root;
        const uint32_t root_id[1] = {0};
        root.assign(root_id, asset.bvh().nodes.size());
        check_samples(asset, root);

        TrainOptions o = default_train_options(BackendChoice::cpu);
        o.steps = 30;
        o.batch_size = 256;
        o.target_nodes = 15;
        o.network.log2_hash_size = 10;
        auto backend = make_backend(BackendChoice::cpu, asset, o);
        const TrainResult r = train_asset(asset, o, *backend);
        EXPECT_EQ(r.skipped_steps, 0u); // no non-finite loss or gradient
        for (const StepLog& s : r.log) {
            ASSERT_TRUE(std::isfinite(s.loss.total) && std::isfinite(s.loss.visibility) &&
                        std::isfinite(s.loss.depth) && std::isfinite(s.loss.normal) && std::isfinite(s.loss.albedo));
        }
        for (float w : r.weights.mlp) ASSERT_TRUE(std::isfinite(w));
        for (float w : r.weights.grid) ASSERT_TRUE(std::isfinite(w));
        // The loss moved (the network learns something even in 30 tiny steps).
        EXPECT_LT(r.log.back().loss.total, r.log.front().loss.total);
    }
}

TEST(TrainerNumerics, RaysParallelToFacesAndOriginsOnFacesOrInside) {
    const Scene scene = test::scene_of(test::cube(1.0f));
    const TrainingAsset asset = make_training_asset(scene, 0);
    TrainingCut root;
    const uint32_t root_id[1] = {0};
    root.assign(root_id, asset.bvh().nodes.size());
    const neural::NetworkWeights w = neural::create_network(NeuralConfig{.log2_hash_size = 10}, 1);
    const glm::vec3 dirs[] = {{1, 0, 0}, {0, 1, 0}, {0, 0, -1}, glm::normalize(glm::vec3(1, 1, 0))};
    // Origins: on a face, on an edge, on a corner, inside, outside in a face plane.
    const glm::vec3 origins[] = {{0.0f, 0.5f, 0.5f}, {0.0f, 0.0f, 0.5f}, {0.0f, 0.0f, 0.0f},
                                 {0.5f, 0.5f, 0.5f}, {-1.0f, 0.0f, 1.0f}, {1.0f, 1.0f, 1.0f}};
    uint32_t met = 0;
    for (const glm::vec3& o : origins)
        for (const glm::vec3& d : dirs) {
            const FirstLeaf f = first_leaf_of_cut(asset.bvh(), asset.node_boxes, root, o, d, 1e-5f, asset.min_exit);
            if (f.leaf < 0) continue;
            met++;
            ASSERT_TRUE(std::isfinite(f.t_entry) && std::isfinite(f.t_exit) && f.t_exit >= f.t_entry);
            const glm::vec3 so = o + d * f.t_entry;
            const float len = f.t_exit - f.t_entry;
            const GroundTruth gt = trace_ground_truth(asset, so, d, 0.0f, len, SampleSlot{});
            ASSERT_TRUE(std::isfinite(gt.depth) && finite3(gt.normal));
            neural::SegmentQuery q;
            nb_segment_points(asset.encoding, so, d, 0.0f, len, q.points[0], q.points[1], q.points[2]);
            const neural::Outputs y = neural::forward(w, q, neural::Precision::fp32);
            for (float v : y) ASSERT_TRUE(std::isfinite(v));
        }
    EXPECT_GE(met, 18u);
}

// The ground truth's shared surface rules at their edges (shared/scene_gpu.h): normal mapping with
// degenerate, parallel, huge or non-finite tangents and extreme texels stays a unit vector (or the
// vertex normal); alpha coverage with alpha 0, 1, above 1 and NaN decides without surprises.
TEST(Numerics, NormalMapAndAlphaCoverageAtTheirEdges) {
    const glm::vec3 n(0.0f, 0.0f, 1.0f), texel(0.9f, 0.2f, 0.6f);
    const float inf = INFINITY, nan = std::nanf("");
    for (const glm::vec4& t4 : {glm::vec4(0.0f), glm::vec4(0.0f, 0.0f, 1.0f, 1.0f), glm::vec4(0.0f, 0.0f, -3.0f, -1.0f),
                                glm::vec4(1e-20f, 0.0f, 0.0f, 1.0f), glm::vec4(nan, 0.0f, 0.0f, 1.0f),
                                glm::vec4(inf, 0.0f, 0.0f, 1.0f)}) {
        const glm::vec3 r = nb_normal_map(n, t4, texel, 1.0f);
        EXPECT_EQ(r, n) << t4.x << " " << t4.z; // no usable tangent: the vertex normal
    }
    for (const glm::vec4& t4 : {glm::vec4(1.0f, 0.0f, 0.0f, 1.0f), glm::vec4(1e30f, 0.0f, 1e30f, -1.0f),
                                glm::vec4(1e-10f, 1e-10f, 0.0f, 1.0f)})
        for (const glm::vec3& tx : {glm::vec3(0.0f), glm::vec3(1.0f), glm::vec3(0.5f, 0.5f, 0.0f), texel})
            for (float scale : {0.0f, 1.0f, 1e30f}) {
                const glm::vec3 r = nb_normal_map(n, t4, tx, scale);
                ASSERT_TRUE(finite3(r));
                EXPECT_NEAR(glm::length(r), 1.0f, 1e-5f);
            }
    // tn = 0 (texel 0.5, 0.5, 0.5): no direction; the vertex normal.
    EXPECT_EQ(nb_normal_map(n, glm::vec4(1.0f, 0.0f, 0.0f, 1.0f), glm::vec3(0.5f), 1.0f), n);

    const uint32_t lo = 0u, hi = 0xFFFFFFFFu; // the smallest and largest draws
    EXPECT_FALSE(nb_alpha_covers(NB_ALPHA_BLEND, 0.0f, 0.0f, lo));
    EXPECT_TRUE(nb_alpha_covers(NB_ALPHA_BLEND, 1.0f, 0.0f, hi));
    EXPECT_TRUE(nb_alpha_covers(NB_ALPHA_BLEND, 2.0f, 0.0f, hi));
    EXPECT_FALSE(nb_alpha_covers(NB_ALPHA_BLEND, nan, 0.0f, lo)); // NaN alpha lets the ray through
    EXPECT_FALSE(nb_alpha_covers(NB_ALPHA_MASK, nan, 0.5f, lo));
    EXPECT_TRUE(nb_alpha_covers(NB_ALPHA_MASK, 0.5f, 0.5f, lo)); // glTF: alpha >= cutoff is opaque
    EXPECT_FALSE(nb_alpha_covers(NB_ALPHA_MASK, 0.4999f, 0.5f, hi));
    EXPECT_TRUE(nb_alpha_covers(NB_ALPHA_OPAQUE, nan, 0.5f, lo));
}

// The visibility loss of a soft target is the KL divergence: 0 where the prediction equals the target,
// positive elsewhere, with the BCE's gradient; binary targets keep the plain BCE.
TEST(Numerics, SoftVisibilityTargetsHaveNoLossFloor) {
    float d = 1.0f;
    EXPECT_NEAR(nb_loss_bce(0.3f, 0.3f, d), 0.0f, 1e-6f);
    EXPECT_NEAR(d, 0.0f, 1e-5f);
    EXPECT_GT(nb_loss_bce(0.6f, 0.3f, d), 0.1f);
    EXPECT_GT(d, 0.0f);
    EXPECT_NEAR(nb_loss_bce(0.25f, 1.0f, d), -std::log(0.25f), 1e-6f);
    EXPECT_NEAR(nb_loss_bce(0.25f, 0.0f, d), -std::log(0.75f), 1e-6f);
    for (float t : {1e-7f, 0.5f, 1.0f - 1e-7f})
        for (float y : {0.0f, 1e-6f, 0.5f, 1.0f}) {
            const float v = nb_loss_bce(y, t, d);
            EXPECT_TRUE(std::isfinite(v) && v >= 0.0f && std::isfinite(d)) << y << " " << t;
        }
}
