// Unit tests of the trainer's pieces: ray/box clipping, first leaf of a cut, survival roulette,
// ground truth, texture fetch, schedule sizing, CSV log.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "tests/support/test_support.h"
#include "tests/trainer/trainer_test_scenes.h"
#include "trainer/cpu/cpu_backend.h"
#include "trainer/ground_truth.h"
#include "trainer/model_export.h"
#include "engine/scene/texture_sampler.h"
#include "trainer/trainer.h"

using namespace nbvh;

TEST(TrainingRays, ClipLineToBox) {
    const Aabb box{glm::vec3(0.0f), glm::vec3(1.0f)};
    float t0, t1;
    ASSERT_TRUE(clip_line_to_box({-1.0f, 0.5f, 0.5f}, {1, 0, 0}, box, t0, t1));
    EXPECT_FLOAT_EQ(t0, 1.0f);
    EXPECT_FLOAT_EQ(t1, 2.0f);
    // Origin inside: entry behind the origin (mint = -inf).
    ASSERT_TRUE(clip_line_to_box({0.25f, 0.5f, 0.5f}, {1, 0, 0}, box, t0, t1));
    EXPECT_FLOAT_EQ(t0, -0.25f);
    EXPECT_FLOAT_EQ(t1, 0.75f);
    // Parallel to a slab with the origin exactly on a face: inside, finite interval, no NaN.
    ASSERT_TRUE(clip_line_to_box({0.0f, 0.0f, -2.0f}, {0, 0, 1}, box, t0, t1));
    EXPECT_FLOAT_EQ(t0, 2.0f);
    EXPECT_FLOAT_EQ(t1, 3.0f);
    // Parallel and outside.
    EXPECT_FALSE(clip_line_to_box({1.5f, 0.5f, -2.0f}, {0, 0, 1}, box, t0, t1));
    // Flat box (zero extent in z): an oblique ray gets a zero-length, finite interval.
    const Aabb flat{glm::vec3(0.0f), glm::vec3(1.0f, 1.0f, 0.0f)};
    ASSERT_TRUE(clip_line_to_box({0.5f, 0.5f, 1.0f}, glm::normalize(glm::vec3(0.1f, 0.1f, -1.0f)), flat, t0, t1));
    EXPECT_TRUE(std::isfinite(t0) && std::isfinite(t1));
    EXPECT_NEAR(t0, t1, 1e-6f);
    EXPECT_FALSE(clip_line_to_box({0, 0, 0}, {1, 0, 0}, Aabb{}, t0, t1)); // empty box
}

TEST(TrainingRays, UniformDirectionsAreUnit) {
    Pcg32 rng(1, 2);
    glm::vec3 mean(0.0f);
    for (int i = 0; i < 20000; ++i) {
        const glm::vec3 d = uniform_sphere_direction(rng.next_float(), rng.next_float());
        ASSERT_NEAR(glm::length(d), 1.0f, 1e-5f);
        mean += d / 20000.0f;
    }
    EXPECT_LT(glm::length(mean), 0.03f); // no bias towards a hemisphere
}

namespace {
// Two cubes far apart: the root's children are the two cubes (after enough splits).
Scene two_cubes() {
    Mesh m = test::cube(1.0f, glm::vec3(0.0f));
    const Mesh b = test::cube(1.0f, glm::vec3(4.0f, 0.0f, 0.0f));
    const uint32_t off = uint32_t(m.positions.size());
    m.positions.insert(m.positions.end(), b.positions.begin(), b.positions.end());
    m.normals.insert(m.normals.end(), b.normals.begin(), b.normals.end());
    for (uint32_t i : b.indices) m.indices.push_back(i + off);
    return test::scene_of(m);
}
} // namespace

TEST(TrainingRays, FirstLeafOfCutIsTheNearest) {
    const Scene scene = two_cubes();
    const TrainingAsset asset = make_training_asset(scene, 0);
    const Bvh& bvh = asset.bvh();
    ASSERT_FALSE(bvh.nodes[0].is_leaf());
    TrainingCut cut;
    const uint32_t kids[2] = {bvh.nodes[0].left, bvh.nodes[0].right};
    cut.assign(kids, bvh.nodes.size());
    // Which child holds the cube at x = 0?
    const int near_slot = asset.node_boxes[kids[0]].hi.x < 2.0f ? 0 : 1;
    FirstLeaf f = first_leaf_of_cut(bvh, asset.node_boxes, cut, {-2.0f, 0.5f, 0.5f}, {1, 0, 0}, 1e-5f, asset.min_exit);
    EXPECT_EQ(f.leaf, near_slot);
    EXPECT_NEAR(f.t_entry, 2.0f, 1e-3f);
    f = first_leaf_of_cut(bvh, asset.node_boxes, cut, {7.0f, 0.5f, 0.5f}, {-1, 0, 0}, 1e-5f, asset.min_exit);
    EXPECT_EQ(f.leaf, 1 - near_slot);
    // Origin inside the far cube, looking back: the leaf containing the origin comes first (t_entry < 0).
    f = first_leaf_of_cut(bvh, asset.node_boxes, cut, {4.5f, 0.5f, 0.5f}, {-1, 0, 0}, 1e-5f, asset.min_exit);
    EXPECT_EQ(f.leaf, 1 - near_slot);
    EXPECT_LT(f.t_entry, 0.0f);
    // Pointing away from everything.
    f = first_leaf_of_cut(bvh, asset.node_boxes, cut, {-2.0f, 0.5f, 0.5f}, {0, 1, 0}, 1e-5f, asset.min_exit);
    EXPECT_EQ(f.leaf, -1);
}

TEST(TrainingRays, SurvivalRouletteRedrawsRejectedSamples) {
    const Scene scene = two_cubes();
    const TrainingAsset asset = make_training_asset(scene, 0);
    const Bvh& bvh = asset.bvh();
    TrainingCut cut;
    const uint32_t kids[2] = {bvh.nodes[0].left, bvh.nodes[0].right};
    cut.assign(kids, bvh.nodes.size());
    cut.keep_probability = {0.0f, 1.0f}; // leaf 0 is always rejected
    const TrainingCut* cuts[1] = {&cut};
    uint32_t draws_per_leaf[2] = {0, 0};
    uint64_t draws = 0;
    for (int i = 0; i < 2000; ++i) {
        const TrainingSample s = draw_training_sample(asset, cuts, {7, 1, uint32_t(i)}, draws_per_leaf, draws);
        ASSERT_EQ(s.leaf, 1);
        ASSERT_TRUE(std::isfinite(s.length) && s.length >= 0.0f);
    }
    EXPECT_GT(draws_per_leaf[0], 100u); // rejected draws still count towards p
    EXPECT_EQ(draws_per_leaf[1], 2000u);
    EXPECT_GT(draws, 4000u);
}

TEST(GroundTruth, QuadHitDepthNormalAlbedo) {
    Mesh m;
    test::add_quad(m, {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1});
    const Scene scene = test::scene_of(m, glm::vec3(0.25f, 0.5f, 0.75f));
    const TrainingAsset asset = make_training_asset(scene, 0);
    // Segment from z = 1 to z = -1 through (0.3, 0.6): hit at t = 1 of a length-2 segment.
    const GroundTruth gt = trace_ground_truth(asset, {0.3f, 0.6f, 1.0f}, {0, 0, -1}, 0.0f, 2.0f, SampleSlot{});
    ASSERT_TRUE(gt.hit);
    EXPECT_NEAR(gt.t_hit, 1.0f, 1e-6f);
    EXPECT_NEAR(gt.depth, 1.0f / (2.0f + asset.encoding.depth_pad), 1e-6f);
    EXPECT_NEAR(gt.normal.z, 1.0f, 1e-6f); // not flipped towards the ray
    EXPECT_NEAR(gt.albedo.x, 0.25f, 1e-6f);
    EXPECT_NEAR(gt.albedo.z, 0.75f, 1e-6f);
    // From below: same normal (never flipped).
    const GroundTruth below = trace_ground_truth(asset, {0.3f, 0.6f, -1.0f}, {0, 0, 1}, 0.0f, 2.0f, SampleSlot{});
    ASSERT_TRUE(below.hit);
    EXPECT_NEAR(below.normal.z, 1.0f, 1e-6f);
    // Segment that stops before the surface: miss.
    EXPECT_FALSE(trace_ground_truth(asset, {0.3f, 0.6f, 1.0f}, {0, 0, -1}, 0.0f, 0.5f, SampleSlot{}).hit);
    // Segment starting behind the origin (t_entry < 0) finds the surface behind it.
    EXPECT_TRUE(trace_ground_truth(asset, {0.3f, 0.6f, -0.5f}, {0, 0, -1}, -1.0f, 0.2f, SampleSlot{}).hit);
}

TEST(GroundTruth, TexturedAlbedoIsSrgbDecoded) {
    Mesh m;
    test::add_quad(m, {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1});
    m.uv0 = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    Scene scene = test::scene_of(m, glm::vec3(1.0f));
    Texture t;
    t.width = t.height = 1;
    t.rgba8 = {188, 188, 188, 255}; // sRGB 188/255 ~ linear 0.5
    t.srgb = true;
    scene.textures.push_back(t);
    scene.materials[0].base_color = glm::vec4(0.5f, 1.0f, 1.0f, 1.0f);
    scene.materials[0].base_color_tex.texture = 0;
    const TrainingAsset asset = make_training_asset(scene, 0);
    const GroundTruth gt = trace_ground_truth(asset, {0.3f, 0.6f, 1.0f}, {0, 0, -1}, 0.0f, 2.0f, SampleSlot{});
    ASSERT_TRUE(gt.hit);
    EXPECT_NEAR(gt.albedo.y, 0.5029f, 2e-3f);
    EXPECT_NEAR(gt.albedo.x, 0.5f * 0.5029f, 2e-3f); // factor x texture
}

// The normal map tilts the interpolated normal in the tangent frame, from its own uv set.
TEST(GroundTruth, NormalMapTiltsTheNormalInTangentSpace) {
    Mesh m;
    test::add_quad(m, {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1});
    m.uv1 = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    m.tangents.assign(4, glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));
    Scene scene = test::scene_of(m);
    Texture t;
    t.width = t.height = 1;
    t.rgba8 = {218, 128, 218, 255}; // tangent space (0.710, 0.004, 0.710): 45 degrees towards +x
    scene.textures.push_back(t);
    scene.materials[0].normal_tex.texture = 0;
    scene.materials[0].normal_tex.uv_set = 1;
    const TrainingAsset asset = make_training_asset(scene, 0);
    const GroundTruth gt = trace_ground_truth(asset, {0.3f, 0.6f, 1.0f}, {0, 0, -1}, 0.0f, 2.0f, SampleSlot{});
    ASSERT_TRUE(gt.hit);
    EXPECT_NEAR(gt.normal.x, 0.7071f, 5e-3f);
    EXPECT_NEAR(gt.normal.z, 0.7071f, 5e-3f);
    EXPECT_NEAR(glm::length(gt.normal), 1.0f, 1e-5f);
    // Scale 0 leaves the vertex normal.
    scene.materials[0].normal_scale = 0.0f;
    EXPECT_NEAR(trace_ground_truth(make_training_asset(scene, 0), {0.3f, 0.6f, 1.0f}, {0, 0, -1}, 0.0f, 2.0f, SampleSlot{}).normal.z,
                1.0f, 1e-6f);
    // Without tangents (or without the map's uv set) the vertex normal.
    scene.materials[0].normal_scale = 1.0f;
    scene.materials[0].normal_tex.uv_set = 0;
    EXPECT_NEAR(trace_ground_truth(make_training_asset(scene, 0), {0.3f, 0.6f, 1.0f}, {0, 0, -1}, 0.0f, 2.0f, SampleSlot{}).normal.z,
                1.0f, 1e-6f);
}

TEST(TextureSampler, BilinearWrap) {
    Texture t;
    t.width = 2;
    t.height = 1;
    t.rgba8 = {0, 0, 0, 255, 255, 255, 255, 255};
    // Texel centres.
    EXPECT_NEAR(sample_texture_bilinear(t, {0.25f, 0.5f}, false).x, 0.0f, 1e-6f);
    EXPECT_NEAR(sample_texture_bilinear(t, {0.75f, 0.5f}, false).x, 1.0f, 1e-6f);
    // Halfway between texel 1 and (wrapped) texel 0.
    EXPECT_NEAR(sample_texture_bilinear(t, {1.0f, 0.5f}, false).x, 0.5f, 1e-6f);
    EXPECT_NEAR(sample_texture_bilinear(t, {-0.25f, 0.5f}, false).x, 1.0f, 1e-6f); // wrap
    EXPECT_NEAR(sample_texture_bilinear(t, {0.75f, 0.5f}, true).x, 1.0f, 1e-6f);
    EXPECT_TRUE(std::isfinite(sample_texture_bilinear(t, {NAN, 1e30f}, true).x));
}

TEST(Schedule, ReachesTargetNodeCount) {
    for (uint32_t target : {31u, 200u, 1000u, 2395u}) {
        TrainOptions o = default_train_options(BackendChoice::cpu);
        o.target_nodes = target;
        const SplitSchedule s = make_split_schedule(o);
        EXPECT_GE(simulate_split_schedule(s).nodes, target) << target;
        EXPECT_LE(s.last_split_iteration, o.steps);
    }
    TrainOptions bad = default_train_options(BackendChoice::cpu);
    bad.steps = 0;
    EXPECT_THROW(validate(bad), Error);
    bad = default_train_options(BackendChoice::cpu);
    bad.lods = 99;
    EXPECT_THROW(validate(bad), Error);
}

TEST(Trainer, GrowsTheCutToTheTargetAndWritesTheLog) {
    const Scene scene = test::scene_of(test::height_field(16, 0.2f, 1.0f, glm::vec3(0.0f)));
    const TrainingAsset asset = make_training_asset(scene, 0);
    TrainOptions o = default_train_options(BackendChoice::cpu);
    o.steps = 40;
    o.batch_size = 256;
    o.target_nodes = 41;
    o.lods = 2;
    o.network.log2_hash_size = 10;
    auto backend = make_backend(BackendChoice::cpu, asset, o);
    uint32_t progress_calls = 0;
    const TrainResult r = train_asset(asset, o, *backend, [&](const TrainProgress&) { progress_calls++; });
    EXPECT_EQ(progress_calls, o.steps);
    EXPECT_TRUE(r.tree.frozen());
    EXPECT_LE(r.tree.node_count(), o.target_nodes);
    EXPECT_GE(r.tree.node_count(), o.target_nodes / 2);
    EXPECT_LE(r.tree.node_count_at(1), r.tree.node_count_at(0)); // LoD 1 is coarser
    EXPECT_EQ(r.skipped_steps, 0u);
    // The learning rate decays in the final stage.
    EXPECT_LT(r.log.back().learning_rate, r.log.front().learning_rate);
    const auto path = test::temp_dir("trainer_log") / "log.csv";
    write_train_log_csv(r.log, path.string());
    std::ifstream f(path);
    std::string header;
    std::getline(f, header);
    EXPECT_EQ(header.rfind("step,nodes,leaves,lr,loss", 0), 0u);
    uint32_t lines = 0;
    for (std::string line; std::getline(f, line);) lines++;
    EXPECT_EQ(lines, o.steps);

    // The model file round-trips what was trained.
    const NeuralModel m = make_neural_model(asset, r, o, "test", 0);
    const NeuralModel back = parse_model(serialize_model(m));
    EXPECT_EQ(back.nodes.size(), r.tree.node_count());
    EXPECT_EQ(back.lod_count, o.lods);
    EXPECT_EQ(back.mlp.size(), size_t(NB_MLP_WEIGHT_COUNT));
    EXPECT_EQ(back.grid.size(), r.weights.grid.size());
    EXPECT_EQ(back.meta.steps, o.steps);
    EXPECT_EQ(back.meta.backend, "cpu");
    EXPECT_EQ(back.encoding_box.lo, asset.bounds.lo);
}

// Several assets (training_asset.h): each part is one subtree of the joined base BVH, its triangles in
// its own atlas cell, the leaf-order vertices match the primitive order (the joined tree orders the
// parts by its top tree, not by part index), and the first-leaf search from a part's root stays in it.
TEST(TrainingAsset, PartsAreDisjointSubtreesOfTheJoinedBvh) {
    Scene s = test::scene_of(test::cube(1.0f));
    for (int k = 1; k < 6; ++k) {
        Mesh m = test::cube(0.3f + 0.2f * float(k), glm::vec3(float(k), 0.5f * float(k), 0.0f));
        m.name = "box" + std::to_string(k);
        m.triangle_material.assign(m.triangle_count(), 0u);
        s.meshes.push_back(std::move(m));
        Instance i;
        i.mesh = uint32_t(k);
        i.neural = true;
        s.instances.push_back(i);
    }
    const std::vector<uint32_t> meshes = neural_meshes(s);
    ASSERT_EQ(meshes.size(), 6u);
    const TrainingAsset a = make_training_asset(s, meshes);
    ASSERT_EQ(a.parts.size(), 6u);
    const Bvh& bvh = a.bvh();
    for (size_t k = 0; k < bvh.prim_indices.size(); ++k)
        for (int c = 0; c < 3; ++c)
            ASSERT_EQ(a.mesh_bvh.vertices[3 * k + c], a.mesh->positions[a.mesh->indices[3 * bvh.prim_indices[k] + c]]);
    for (size_t p = 0; p < a.parts.size(); ++p) {
        const TrainingPart& part = a.parts[p];
        EXPECT_NEAR(std::max({part.bounds.extent().x, part.bounds.extent().y, part.bounds.extent().z}), 1.0f, 1e-3f);
        EXPECT_EQ(a.above_parts[part.root], 0);
        // Every leaf under the root holds only this part's triangles.
        std::vector<uint32_t> stack{part.root};
        uint32_t tris = 0;
        while (!stack.empty()) {
            const BvhNode& n = bvh.nodes[stack.back()];
            stack.pop_back();
            if (!n.is_leaf()) {
                stack.push_back(n.left);
                stack.push_back(n.right);
                continue;
            }
            for (uint32_t i = n.first; i < n.first + n.count; ++i) {
                const uint32_t t = bvh.prim_indices[i];
                EXPECT_GE(t, part.first_triangle);
                EXPECT_LT(t, part.first_triangle + part.triangle_count);
                ++tris;
            }
        }
        EXPECT_EQ(tris, part.triangle_count);
        // Rays from the part's sampling box find leaves of its subtree only, and their ground truth hits it.
        TrainingCut cut;
        std::vector<uint32_t> leaves;
        for (uint32_t i = 0; i < bvh.nodes.size(); ++i)
            if (bvh.nodes[i].is_leaf()) leaves.push_back(i);
        cut.assign(leaves, bvh.nodes.size());
        const glm::vec3 c = part.bounds.center();
        const FirstLeaf f = first_leaf_of_cut(bvh, a.node_boxes, cut, c + glm::vec3(0, 0, 2), glm::vec3(0, 0, -1), 1e-5f,
                                              a.min_exit, part.root);
        ASSERT_GE(f.leaf, 0);
        const BvhNode& leaf = bvh.nodes[cut.leaves[size_t(f.leaf)]];
        EXPECT_GE(bvh.prim_indices[leaf.first], part.first_triangle);
        EXPECT_LT(bvh.prim_indices[leaf.first], part.first_triangle + part.triangle_count);
    }
}

// The hit probability p of the split heuristic (paper §3.2: h = q sqrt(p)) is the probability that a
// training ray meets the leaf first. The survival roulette redraws rejected samples, so the rays drawn
// per step grow as the roulette rejects more; p must not count that growth (draws / steps alive did:
// a leaf that lived through cheap steps looked rarer than a newer leaf of half its true probability).
// A scripted backend: root -> A, B (A has the larger error and is split next) -> A1, A2, B, with true
// probabilities A1 = A2 = 1/4, B = 1/2 and ten times more rays drawn per step once A is split. With an
// unbiased p and equal q, keep(B) = 1 and keep(A1) = keep(A2) = sqrt(1/2) at every step after that.
namespace {
class ScriptedBackend final : public TrainerBackend {
public:
    const char* name() const override { return "scripted"; }
    StepStats step(const StepParams& params) override {
        const TrainingCut& cut = *params.cuts[0];
        StepStats st;
        st.leaves.resize(cut.size());
        auto set = [&](size_t slot, uint32_t draws, double loss_per_sample) {
            st.leaves[slot].draws = draws;
            st.leaves[slot].samples = std::max(1u, draws / 10);
            st.leaves[slot].loss_sum = loss_per_sample * st.leaves[slot].samples;
            st.draws += draws;
            st.samples += st.leaves[slot].samples;
        };
        if (cut.size() == 1) {
            set(0, 100, 1.0);
        } else if (cut.size() == 2) {
            a_ = cut.leaves[0];
            b_ = cut.leaves[1];
            two_leaf_steps++;
            set(0, 50, 2.0); // A: larger error, split next
            set(1, 50, 1.0);
        } else {
            three_leaf_steps++;
            for (size_t i = 0; i < cut.size(); ++i) {
                const bool b = cut.leaves[i] == b_;
                if (b) b_slot = int(i);
                set(i, b ? 500 : 250, 1.0); // 10x the rays drawn per step
            }
            if (three_leaf_steps >= 2) keeps.push_back(cut.keep_probability); // A1/A2 have statistics
        }
        st.loss.total = 1.0;
        return st;
    }
    void read_weights(neural::NetworkWeights& out) const override { out = {}; }

    uint32_t two_leaf_steps = 0, three_leaf_steps = 0;
    int b_slot = -1;
    std::vector<std::vector<float>> keeps;

private:
    uint32_t a_ = 0, b_ = 0;
};
} // namespace

TEST(Trainer, HitProbabilityIsUnbiasedByRedraws) {
    const Scene scene = test::scene_of(test::height_field(16, 0.2f, 1.0f, glm::vec3(0.0f)));
    const TrainingAsset asset = make_training_asset(scene, 0);
    TrainOptions o = default_train_options(BackendChoice::cpu);
    o.steps = 400;
    o.target_nodes = 5;
    o.lods = 1; // the scripted backend reports one cut
    ScriptedBackend backend;
    const TrainResult r = train_asset(asset, o, backend);
    EXPECT_EQ(r.tree.node_count(), 5u);
    ASSERT_GE(backend.two_leaf_steps, 3u);
    ASSERT_FALSE(backend.keeps.empty());
    ASSERT_GE(backend.b_slot, 0);
    for (const std::vector<float>& keep : backend.keeps) {
        ASSERT_EQ(keep.size(), 3u);
        for (size_t i = 0; i < 3; ++i)
            EXPECT_NEAR(keep[i], int(i) == backend.b_slot ? 1.0f : std::sqrt(0.5f), 1e-4f) << i;
    }
}
