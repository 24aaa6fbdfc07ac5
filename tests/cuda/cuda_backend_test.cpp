// CUDA backend vs the CPU reference (issue 5 acceptance): the same rays are drawn, the GPU ground truth
// matches the CPU tracer, the step's loss and gradients match the CPU reference network run on the
// GPU's samples within fp16 bounds (deterministic mode), runs are reproducible, a short training run
// follows the CPU loss curve, hard assets train without NaN, and a huge learning rate is caught by the
// non-finite guard, as is an overflowing loss scale. Every test skips without a usable CUDA GPU.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numeric>

#include "engine/neural/losses.h"
#include "engine/scene/gltf_loader.h"
#include "tests/cuda/cuda_test_support.h"
#include "tests/support/test_support.h"
#include "tests/trainer/trainer_test_scenes.h"
#include "trainer/cpu/cpu_backend.h"
#include "trainer/cuda/cuda_backend.h"
#include "trainer/ground_truth.h"
#include "trainer/trainer.h"

namespace nbvh {
namespace {

using test::cut_at_depth;
using test::fixed_cut_step;

Scene load_bunny() {
    SceneLoadOptions lo;
    lo.neural_glob = "*";
    return load_gltf(test::scenes_dir() / "stanford_bunny" / "stanford_bunny.glb", lo);
}

double rel_l2(const std::vector<float>& a, const std::vector<double>& b) {
    double num = 0, den = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        num += (double(a[i]) - b[i]) * (double(a[i]) - b[i]);
        den += b[i] * b[i];
    }
    return std::sqrt(num / std::max(den, 1e-300));
}

// The GPU's samples against the CPU backend's: same rays (same PCG32 streams; float differences in
// sin/cos may move a rare ray, so 1 % may differ) and the same ground truth (hit, depth, normal, albedo
// with per-hit texture lookups).
// Also the draw counts: the GPU spreads a slot's attempts over its warp's idle lanes (sampling_kernels.cu
// k_sample) and must count exactly the attempts up to the first kept one, per leaf and in total.
// The cuts are p.cuts (several: levels of detail, one picked per attempt; draws counted for cuts[0] only).
uint32_t check_rays_and_truth(const TrainingAsset& asset, const StepParams& p, const StepStats& st,
                              const std::vector<CudaDebugSample>& samples) {
    uint32_t same = 0;
    uint64_t draws = 0;
    std::vector<uint32_t> leaf_draws(p.cuts[0]->size(), 0u);
    for (uint32_t i = 0; i < p.batch_size; ++i) {
        const TrainingSample s = draw_training_sample(asset, p.cuts, {p.seed, p.step, i}, leaf_draws.data(), draws);
        if (s.leaf == samples[i].leaf && s.cut == samples[i].cut &&
            glm::length(s.origin - samples[i].origin) <= 1e-4f * glm::length(asset.bounds.extent()))
            same++;
    }
    EXPECT_GE(same, p.batch_size * 99 / 100);
    EXPECT_GT(draws, uint64_t(p.batch_size)); // misses and the roulette's rejections are redrawn
    // A ray moved by sin/cos rounding changes a few counts; the attempts themselves must line up.
    EXPECT_NEAR(double(st.draws), double(draws), 0.002 * double(draws));
    EXPECT_EQ(st.leaves.size(), leaf_draws.size());
    if (st.leaves.size() != leaf_draws.size()) return same;
    uint64_t off = 0, total = 0;
    for (size_t l = 0; l < leaf_draws.size(); ++l) {
        off += uint64_t(std::llabs(int64_t(st.leaves[l].draws) - int64_t(leaf_draws[l])));
        total += leaf_draws[l];
    }
    EXPECT_LE(off, total / 200) << "per-leaf draws differ from the CPU sampler's";

    // 2. Ground truth: the GPU tracer agrees with the CPU tracer on hit/miss and depth.
    uint32_t hit_mismatch = 0, depth_off = 0, normal_off = 0, albedo_off = 0;
    for (uint32_t i = 0; i < uint32_t(samples.size()); ++i) {
        const CudaDebugSample& s = samples[i];
        const GroundTruth gt = trace_ground_truth(asset, s.origin, s.dir, 0.0f, s.length, SampleSlot{p.seed, p.step, i});
        if (std::fabs(gt.visibility - s.target[0]) > 1e-3f) { hit_mismatch++; continue; }
        if (!gt.hit) continue;
        if (std::fabs(gt.depth - s.target[1]) > 1e-4f) depth_off++;
        const glm::vec3 n((s.target[2] * 2 - 1), (s.target[3] * 2 - 1), (s.target[4] * 2 - 1));
        if (glm::dot(n, gt.normal) < 0.999f) normal_off++;
        const glm::vec3 al(s.target[5], s.target[6], s.target[7]);
        if (glm::length(al - gt.albedo) > 1e-3f) albedo_off++;
    }
    EXPECT_LE(hit_mismatch, p.batch_size / 500);
    EXPECT_LE(depth_off, p.batch_size / 500);
    EXPECT_LE(normal_off, p.batch_size / 500);
    EXPECT_LE(albedo_off, p.batch_size / 500);
    return same;

}

void check_against_cpu(bool deterministic, uint32_t batch) {
    const Scene scene = load_bunny();
    const TrainingAsset asset = make_training_asset(scene, pick_neural_mesh(scene));
    TrainingCut cut = cut_at_depth(asset, 6);
    for (size_t i = 0; i < cut.size(); ++i) cut.keep_probability[i] = i % 3 == 0 ? 0.5f : 1.0f;
    const NeuralConfig cfg{.log2_hash_size = 14};
    neural::AdamConfig adam;
    CudaBackendOptions opt;
    opt.deterministic = deterministic;
    auto gpu = make_cuda_backend_ex(asset, cfg, adam, opt, 7);
    StepParams p;
    p.step = 3;
    p.batch_size = batch;
    p.seed = 99;
    p.cuts = {&cut};
    p.cut_version = 1;
    const StepStats st = gpu->step(p);
    ASSERT_FALSE(st.skipped) << st.skip_reason;
    ASSERT_EQ(st.samples, p.batch_size);
    std::vector<CudaDebugSample> samples;
    std::vector<float> mlp_grad, grid_grad;
    gpu->read_last_step(samples, mlp_grad, grid_grad);

    const uint32_t same = check_rays_and_truth(asset, p, st, samples);

    // 3. Loss and gradients: CPU reference network (fp16-emulated forward = the shaders' rounding) on the
    //    GPU's samples and targets, with the initial weights (same init for the seed).
    const neural::NetworkWeights w = neural::create_network(cfg, 7);
    const neural::LossConfig lc;
    std::vector<double> cpu_mlp(mlp_grad.size(), 0.0), cpu_grid(grid_grad.size(), 0.0);
    double loss_sum = 0.0;
    uint32_t n = 0;
    neural::ForwardCache cache;
    neural::Gradients g;
    for (const CudaDebugSample& s : samples) {
        if (s.leaf < 0) continue;
        neural::SegmentQuery q;
        nb_segment_points(asset.encoding, s.origin, s.dir, 0.0f, s.length, q.points[0], q.points[1], q.points[2]);
        const neural::Outputs y = neural::forward(w, q, neural::Precision::fp16_emulated, &cache);
        neural::Targets t;
        for (int k = 0; k < 8; ++k) t[k] = s.target[k];
        neural::Outputs dl{};
        loss_sum += neural::composite_loss(y, t, lc, &dl);
        g.reset();
        neural::backward(w, cache, dl, g);
        for (size_t i = 0; i < g.mlp.size(); ++i) cpu_mlp[i] += g.mlp[i];
        for (const auto& gg : g.grid) cpu_grid[gg.index] += gg.grad;
        n++;
    }
    for (double& v : cpu_mlp) v /= n;
    for (double& v : cpu_grid) v /= n;
    const double cpu_loss = loss_sum / n;
    EXPECT_NEAR(st.loss.total, cpu_loss, 2e-3 * cpu_loss + 1e-6);
    // Bounds: fp16 activations and fp16 loss-scaled backward vs the CPU's fp32 backward.
    const double e_mlp = rel_l2(mlp_grad, cpu_mlp), e_grid = rel_l2(grid_grad, cpu_grid);
    std::printf("loss gpu %.6f cpu %.6f; gradient rel L2 error: mlp %.3e grid %.3e; same rays %u/%u\n",
                st.loss.total, cpu_loss, e_mlp, e_grid, same, p.batch_size);
    EXPECT_LT(e_mlp, 2e-2);
    EXPECT_LT(e_grid, 2e-2);
}

TEST(CudaBackend, SamplesTruthLossAndGradientsMatchCpuReference) {
    REQUIRE_GPU();
    NBVH_REQUIRE_SHARED();
    check_against_cpu(true, 4096);
}

// Fast mode (fp32 atomics, shared-memory accumulation of the coarse levels): same bounds. The batch is not a
// multiple of 16, so the MLP's partial last warp tile (zero rows, masked dL/dfeature stores) is checked too.
TEST(CudaBackend, FastModeGradientsMatchCpuReference) {
    REQUIRE_GPU();
    NBVH_REQUIRE_SHARED();
    check_against_cpu(false, 4090);
}

// One deterministic step on `scene`'s asset; the GPU's rays and ground truth against the CPU's
// (check_rays_and_truth). Returns the samples and the step's parameters.
std::vector<CudaDebugSample> step_and_check(const TrainingAsset& asset, StepParams& p) {
    TrainingCut cut = cut_at_depth(asset, 2);
    CudaBackendOptions opt;
    opt.deterministic = true;
    auto gpu = make_cuda_backend_ex(asset, NeuralConfig{.log2_hash_size = 12}, neural::AdamConfig{}, opt, 7);
    p.step = 3;
    p.batch_size = 8192;
    p.seed = 99;
    p.cuts = {&cut};
    p.cut_version = 1;
    const StepStats st = gpu->step(p);
    EXPECT_FALSE(st.skipped) << st.skip_reason;
    std::vector<CudaDebugSample> samples;
    std::vector<float> mlp_grad, grid_grad;
    gpu->read_last_step(samples, mlp_grad, grid_grad);
    check_rays_and_truth(asset, p, st, samples); // <= 1 in 500 samples may differ
    p.cuts.clear();
    return samples;
}

// The GPU's samples whose CPU ground truth (same keys) differs between `asset` and `variant` by `differs`:
// how many samples a feature decides, i.e. how many a GPU that ignored it would get wrong.
template <class Differs>
uint32_t count_differing(const TrainingAsset& asset, const TrainingAsset& variant,
                         const std::vector<CudaDebugSample>& samples, const StepParams& p, Differs differs) {
    uint32_t n = 0;
    for (uint32_t i = 0; i < uint32_t(samples.size()); ++i) {
        const CudaDebugSample& s = samples[i];
        if (s.leaf < 0) continue;
        const SampleSlot key{p.seed, p.step, i};
        n += differs(trace_ground_truth(asset, s.origin, s.dir, 0.0f, s.length, key),
                     trace_ground_truth(variant, s.origin, s.dir, 0.0f, s.length, key));
    }
    return n;
}

// Alpha-tested surfaces (trainer/ground_truth.cpp alpha_covers): the GPU's ground truth cuts MASK holes
// and draws BLEND coverage exactly as the CPU's, sample by sample (same key, same draw).
TEST(CudaBackend, AlphaCoverageGroundTruthMatchesTheCpu) {
    REQUIRE_GPU();
    const Scene scene = test::alpha_quads_scene();
    const TrainingAsset asset = make_training_asset(scene, 0);
    ASSERT_TRUE(asset.alpha_tested);
    StepParams p;
    const std::vector<CudaDebugSample> samples = step_and_check(asset, p);
    // Enough samples where alpha decides for a GPU that ignored it to fail the check.
    Scene opaque_scene = scene;
    for (Material& m : opaque_scene.materials) m.alpha_mode = AlphaMode::opaque;
    const TrainingAsset opaque = make_training_asset(opaque_scene, 0);
    const uint32_t decided = count_differing(asset, opaque, samples, p, [](const GroundTruth& a, const GroundTruth& o) {
        return a.hit != o.hit || a.t_hit != o.t_hit || a.visibility != o.visibility;
    });
    std::printf("samples where alpha decides: %u of %u\n", decided, p.batch_size);
    EXPECT_GT(decided, p.batch_size / 50);
}

// Normal maps (trainer/ground_truth.cpp shading_normal, shared/scene_gpu.h nb_normal_map): the GPU's
// ground-truth normals match the CPU's (own uv set, texture transform, handedness, scale), and the map
// moves enough of them for a GPU that ignored it to fail.
TEST(CudaBackend, NormalMapGroundTruthMatchesTheCpu) {
    REQUIRE_GPU();
    const Scene scene = test::normal_mapped_scene();
    const TrainingAsset asset = make_training_asset(scene, 0);
    StepParams p;
    const std::vector<CudaDebugSample> samples = step_and_check(asset, p);
    Scene plain_scene = scene;
    plain_scene.materials[0].normal_tex.texture = -1;
    const TrainingAsset plain = make_training_asset(plain_scene, 0);
    const uint32_t moved = count_differing(asset, plain, samples, p, [](const GroundTruth& a, const GroundTruth& o) {
        return a.hit && glm::dot(a.normal, o.normal) < 0.99f;
    });
    std::printf("samples whose normal the map moves: %u of %u\n", moved, p.batch_size);
    EXPECT_GT(moved, p.batch_size / 50);
}

TEST(CudaBackend, DeterministicModeIsBitReproducible) {
    REQUIRE_GPU();
    const test::MeshAsset m(test::height_field(32, 0.2f, 1.0f, glm::vec3(0.0f)));
    const TrainingAsset& asset = m.asset;
    TrainingCut cut = cut_at_depth(asset, 5);
    CudaBackendOptions opt;
    opt.deterministic = true;
    const NeuralConfig cfg{.log2_hash_size = 12};
    std::vector<neural::NetworkWeights> w(2);
    for (int r = 0; r < 2; ++r) {
        auto b = make_cuda_backend_ex(asset, cfg, neural::AdamConfig{}, opt, 3);
        for (uint32_t s = 0; s < 4; ++s) ASSERT_FALSE(b->step(fixed_cut_step(s, 3000, 5, cut)).skipped);
        b->read_weights(w[r]);
    }
    EXPECT_EQ(w[0].mlp, w[1].mlp);
    EXPECT_EQ(w[0].grid, w[1].grid);
}

TEST(CudaBackend, ShortTrainingFollowsTheCpuLossCurve) {
    REQUIRE_GPU();
    NBVH_REQUIRE_SHARED();
    const Scene scene = load_bunny();
    const TrainingAsset asset = make_training_asset(scene, pick_neural_mesh(scene));
    TrainOptions o = default_train_options(BackendChoice::cpu);
    o.steps = 150;
    o.batch_size = 4096;
    o.target_nodes = 300;
    o.network.log2_hash_size = 15;
    double tail[2] = {0, 0};
    for (int k = 0; k < 2; ++k) {
        auto backend = make_backend(k == 0 ? BackendChoice::cpu : BackendChoice::cuda, asset, o);
        const TrainResult r = train_asset(asset, o, *backend);
        EXPECT_EQ(r.skipped_steps, 0u);
        for (size_t s = r.log.size() - 30; s < r.log.size(); ++s) tail[k] += r.log[s].loss.total / 30.0;
        std::printf("%s: first loss %.4f, mean of the last 30 steps %.4f, %.0f samples/s\n", r.backend.c_str(),
                    r.log.front().loss.total, tail[k], r.samples_per_s);
    }
    EXPECT_NEAR(tail[1], tail[0], 0.1 * tail[0]); // same curve within noise (different rays per step)
}

TEST(CudaBackend, HardAssetsTrainWithoutNonFiniteValues) {
    REQUIRE_GPU();
    struct Case { const char* name; Mesh mesh; };
    std::vector<Case> cases;
    cases.push_back({"flat plane", test::height_field(16, 0.0f, 1.0f, glm::vec3(0.0f))});
    cases.push_back({"tiny (1e-3)", test::height_field(16, 0.2f, 1e-3f, glm::vec3(0.0f))});
    cases.push_back({"huge (1e4)", test::height_field(16, 0.2f, 1e4f, glm::vec3(0.0f))});
    cases.push_back({"far from the origin", test::cube(1.0f, glm::vec3(1e5f, -2e5f, 3e4f))});
    cases.push_back({"single cube", test::cube()});
    for (Case& c : cases) {
        SCOPED_TRACE(c.name);
        const Scene scene = test::scene_of(std::move(c.mesh));
        const TrainingAsset asset = make_training_asset(scene, 0);
        TrainOptions o = default_train_options(BackendChoice::cpu);
        o.steps = 40;
        o.batch_size = 2048;
        o.target_nodes = 15;
        o.network.log2_hash_size = 10;
        auto backend = make_backend(BackendChoice::cuda, asset, o);
        const TrainResult r = train_asset(asset, o, *backend);
        EXPECT_EQ(r.skipped_steps, 0u);
        for (const StepLog& s : r.log) ASSERT_TRUE(std::isfinite(s.loss.total));
        EXPECT_NO_THROW(neural::validate_network(r.weights));
    }
}

// `steps` steps of `batch` samples on `cut`: every skipped step names `reason`, every trained one has a
// finite loss; returns the skipped count. Then the master weights must be finite.
uint32_t run_guarded_steps(CudaTrainerBackend& b, const TrainingCut& cut, uint32_t steps, uint32_t batch,
                           uint64_t seed, const char* reason) {
    uint32_t skipped = 0;
    for (uint32_t s = 0; s < steps; ++s) {
        const StepStats st = b.step(fixed_cut_step(s, batch, seed, cut));
        if (st.skipped) {
            skipped++;
            EXPECT_NE(st.skip_reason.find(reason), std::string::npos) << st.skip_reason;
        } else {
            EXPECT_TRUE(std::isfinite(st.loss.total));
        }
    }
    neural::NetworkWeights w;
    b.read_weights(w);
    const auto non_finite = [](const std::vector<float>& v) {
        return std::count_if(v.begin(), v.end(), [](float x) { return !std::isfinite(x); });
    };
    EXPECT_EQ(non_finite(w.mlp), 0);
    EXPECT_EQ(non_finite(w.grid), 0);
    return skipped;
}

TEST(CudaBackend, HugeLearningRateIsCaughtByTheGuard) {
    REQUIRE_GPU();
    const test::MeshAsset m(test::cube());
    TrainingCut cut = cut_at_depth(m.asset, 3);
    neural::AdamConfig adam;
    adam.learning_rate = 1e30f;
    auto b = make_cuda_backend_ex(m.asset, NeuralConfig{.log2_hash_size = 10}, adam, CudaBackendOptions{}, 1);
    // The first step blows the fp16 weights up; later steps are refused.
    EXPECT_GE(run_guarded_steps(*b, cut, 5, 1024, 1, "non-finite"), 1u);
}

// A loss scale of 65536 overflows the fp16 backward at the first steps (|dL/dz| x 65536 > 65504): the
// guard skips those steps and halves the scale until the gradients are finite; no non-finite value
// reaches the weights.
TEST(CudaBackend, OverflowingLossScaleIsHalvedByTheGuard) {
    REQUIRE_GPU();
    const test::MeshAsset m(test::height_field(16, 0.2f, 1.0f, glm::vec3(0.0f)));
    TrainingCut cut = cut_at_depth(m.asset, 4);
    CudaBackendOptions opt;
    opt.loss_scale = 65536.0f;
    auto b = make_cuda_backend_ex(m.asset, NeuralConfig{.log2_hash_size = 12}, neural::AdamConfig{}, opt, 3);
    const uint32_t skipped = run_guarded_steps(*b, cut, 24, 4096, 3, "non-finite gradient");
    EXPECT_GE(skipped, 1u);
    EXPECT_LT(skipped, 24u);
    EXPECT_LT(b->loss_scale(), 65536.0f);
}

// The fast mode sums the grid gradients in fp16 (as tiny-cuda-nn): the fine levels' in global memory,
// the coarse levels' per-block partials in shared memory. A batch of 2^16 samples on one small quad at a
// loss scale of 16384 overflows such sums (the guard names a non-finite gradient; which sum overflowed,
// a fine level's or a coarse partial, is not told apart here). The guard must see it before Adam: steps
// skipped, the scale halved, finite weights.
TEST(CudaBackend, OverflowingFp16GridGradientsAreGuarded) {
    REQUIRE_GPU();
    Mesh quad;
    test::add_quad(quad, {0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 0.0f}, {0.0f, 1.0f, 0.0f},
                   {0, 0, 1});
    const test::MeshAsset m(std::move(quad));
    TrainingCut cut = cut_at_depth(m.asset, 0);
    CudaBackendOptions opt;
    opt.loss_scale = 16384.0f;
    auto b = make_cuda_backend_ex(m.asset, NeuralConfig{.log2_hash_size = 14}, neural::AdamConfig{}, opt, 5);
    const uint32_t skipped = run_guarded_steps(*b, cut, 6, 65536, 5, "non-finite gradient");
    std::printf("fp16 grid gradients at loss scale 16384: %u of 6 steps skipped, scale now %.0f\n", skipped,
                b->loss_scale());
    EXPECT_GE(skipped, 1u);
    EXPECT_LT(b->loss_scale(), 16384.0f);
}

} // namespace
// Several assets, one textured (base-colour texture with a KHR_texture_transform): the CUDA sampler
// picks the part and searches its subtree as the CPU does, and its ground truth samples the texture
// per hit (was: per vertex) to the CPU's values.
TEST(CudaBackend, MultiAssetTexturedTruthMatchesCpu) {
    REQUIRE_GPU();
    Scene s = test::scene_of(test::cube(1.0f));
    Texture tex;
    tex.width = 16;
    tex.height = 8;
    tex.srgb = true;
    for (uint32_t y = 0; y < tex.height; ++y)
        for (uint32_t x = 0; x < tex.width; ++x)
            for (uint8_t c : {uint8_t(x * 16), uint8_t(y * 32), uint8_t(((x ^ y) & 1) * 255), uint8_t(255)})
                tex.rgba8.push_back(c);
    s.textures.push_back(tex);
    s.materials[0].base_color_tex.texture = 0;
    s.materials[0].base_color_tex.transform = glm::mat3(glm::vec3(2.0f, 0.0f, 0.0f), glm::vec3(0.0f, 1.5f, 0.0f),
                                                        glm::vec3(0.25f, 0.1f, 1.0f));
    Mesh& m0 = s.meshes[0];
    m0.uv0.clear();
    for (const glm::vec3& p : m0.positions) m0.uv0.push_back(glm::vec2(p.x + 0.3f * p.z, p.y - 0.2f * p.z));
    for (int k = 1; k < 3; ++k) {
        Mesh m = test::cube(0.4f + 0.3f * float(k), glm::vec3(float(k), 0.0f, 0.0f));
        m.name = "cube" + std::to_string(k);
        m.triangle_material.assign(m.triangle_count(), 0u);
        m.uv0.assign(m.positions.size(), glm::vec2(0.1f * float(k), 0.7f));
        s.meshes.push_back(std::move(m));
        Instance i;
        i.mesh = uint32_t(k);
        i.neural = true;
        s.instances.push_back(i);
    }
    const TrainingAsset asset = make_training_asset(s, neural_meshes(s));
    ASSERT_EQ(asset.parts.size(), 3u);
    // Two levels of detail (each attempt picks one; only the finer one's draws are counted) and a
    // roulette on some of the finer cut's leaves.
    TrainingCut cut = cut_at_depth(asset, 5), coarse = cut_at_depth(asset, 3); // part roots are at depth <= 2
    for (size_t i = 0; i < cut.size(); ++i) cut.keep_probability[i] = i % 4 == 1 ? 0.3f : 1.0f;
    auto gpu = make_cuda_backend_ex(asset, NeuralConfig{.log2_hash_size = 14}, neural::AdamConfig{}, CudaBackendOptions{}, 7);
    StepParams p;
    p.step = 1;
    p.batch_size = 4096;
    p.seed = 5;
    p.cuts = {&cut, &coarse};
    p.cut_version = 1;
    const StepStats st = gpu->step(p);
    ASSERT_FALSE(st.skipped) << st.skip_reason;
    std::vector<CudaDebugSample> samples;
    std::vector<float> mlp_grad, grid_grad;
    gpu->read_last_step(samples, mlp_grad, grid_grad);
    uint32_t on_coarse = 0;
    for (const CudaDebugSample& x : samples) on_coarse += x.cut == 1u ? 1u : 0u;
    EXPECT_GT(on_coarse, p.batch_size / 4); // both cuts are sampled
    check_rays_and_truth(asset, p, st, samples);
}

// A cut whose every leaf is rejected: each slot (an odd batch, so the last warp is partial and the
// rounds end with idle lanes) makes exactly kMaxSampleAttempts attempts and is not trained, as on the CPU.
TEST(CudaBackend, UnreachableCutStarvesEverySlotAfterTheSameAttempts) {
    REQUIRE_GPU();
    const Scene scene = test::scene_of(test::cube(1.0f));
    const TrainingAsset asset = make_training_asset(scene, 0);
    TrainingCut cut = cut_at_depth(asset, 2);
    std::fill(cut.keep_probability.begin(), cut.keep_probability.end(), 0.0f);
    auto gpu = make_cuda_backend_ex(asset, NeuralConfig{.log2_hash_size = 14}, neural::AdamConfig{}, CudaBackendOptions{}, 7);
    StepParams p;
    p.step = 2;
    p.batch_size = 37;
    p.seed = 9;
    p.cuts = {&cut};
    p.cut_version = 1;
    const StepStats st = gpu->step(p);
    EXPECT_EQ(st.samples, 0u);
    EXPECT_EQ(st.draws, uint64_t(p.batch_size) * kMaxSampleAttempts);
    std::vector<CudaDebugSample> samples;
    std::vector<float> mlp_grad, grid_grad;
    gpu->read_last_step(samples, mlp_grad, grid_grad);
    ASSERT_EQ(samples.size(), p.batch_size);
    for (const CudaDebugSample& x : samples) EXPECT_EQ(x.leaf, -1);
    uint64_t cpu_draws = 0;
    std::vector<uint32_t> cpu_leaf_draws(cut.size(), 0u);
    for (uint32_t i = 0; i < p.batch_size; ++i)
        EXPECT_EQ(draw_training_sample(asset, p.cuts, {p.seed, p.step, i}, cpu_leaf_draws.data(), cpu_draws).leaf, -1);
    EXPECT_EQ(cpu_draws, st.draws);
    ASSERT_EQ(st.leaves.size(), cut.size());
    uint64_t off = 0, total = 0;
    for (size_t l = 0; l < cut.size(); ++l) {
        off += uint64_t(std::llabs(int64_t(st.leaves[l].draws) - int64_t(cpu_leaf_draws[l])));
        total += cpu_leaf_draws[l];
    }
    EXPECT_GT(total, 0u);
    EXPECT_LE(off, total / 200);
}

} // namespace nbvh
