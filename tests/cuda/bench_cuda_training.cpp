// Benchmark of the CUDA trainer (issue 5), run on the GPU machine; not a test (no timing assertions).
//   bench_cuda_training --scene PATH [--json FILE] [--steps N] [--nodes N] [--skip-train]
// 1. Step throughput at the paper's configuration (batch 2^18, 8 levels x 4 features at T = 2^18,
//    96 -> 64x4 -> 8) on a fixed cut: full-step samples/s and a per-phase breakdown (CUDA events).
// 2. Time to train a model of the paper's size: the official Chess schedule (~25k nodes), 10k steps.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>

#include "engine/core/error.h"
#include "engine/scene/gltf_loader.h"
#include "trainer/cuda/cuda_backend.h"
#include "trainer/trainer.h"

using namespace nbvh;

static double now_s() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

int main(int argc, char** argv) try {
    std::string scene_path, json_out;
    uint32_t steps = 10000, nodes = 25249;
    bool train = true;
    for (int i = 1; i < argc; ++i) {
        const std::string k = argv[i];
        auto val = [&] { if (i + 1 >= argc) throw Error("missing value for " + k); return std::string(argv[++i]); };
        if (k == "--scene") scene_path = val();
        else if (k == "--json") json_out = val();
        else if (k == "--steps") steps = uint32_t(std::stoul(val()));
        else if (k == "--nodes") nodes = uint32_t(std::stoul(val()));
        else if (k == "--skip-train") train = false;
        else throw Error("unknown option " + k);
    }
    if (scene_path.empty()) throw Error("pass --scene PATH (e.g. stanford_dragon/dragon_vrip.glb)");
    if (!cuda_backend_available()) throw Error("no usable CUDA GPU");
    const std::string device = cuda_device_name();
    std::printf("device: %s\n", device.c_str());
    SceneLoadOptions lo;
    lo.neural_glob = "*";
    const double tl = now_s();
    const Scene scene = load_gltf(scene_path, lo);
    const TrainingAsset asset = make_training_asset(scene, pick_neural_mesh(scene));
    std::printf("asset: %s, %u triangles, %zu base nodes (load + BVH %.1f s)\n", asset.name.c_str(),
                asset.triangle_count(), asset.bvh().nodes.size(), now_s() - tl);

    // 1. Step throughput on a fixed cut of ~2.4k leaves (the depth-11 frontier).
    TrainOptions opt = default_train_options(BackendChoice::cuda); // paper config
    std::vector<uint32_t> leaves, stack{0};
    while (!stack.empty()) {
        const uint32_t n = stack.back();
        stack.pop_back();
        const BvhNode& node = asset.bvh().nodes[n];
        if (node.is_leaf() || node.depth >= 11) { leaves.push_back(n); continue; }
        stack.push_back(node.left);
        stack.push_back(node.right);
    }
    TrainingCut cut;
    cut.assign(leaves, asset.bvh().nodes.size());
    StepParams p;
    p.batch_size = opt.batch_size;
    p.seed = opt.seed;
    p.cuts = {&cut};
    p.cut_version = 1;
    // Mean wall time of 100 steps after 20 warm-up, with the next batch drawn during the network part
    // (the default) and without (every phase in sequence).
    auto time_steps = [&](CudaTrainerBackend& b) {
        for (uint32_t s = 0; s < 20; ++s) { p.step = s; b.step(p); }
        const uint32_t timed = 100;
        const double t0 = now_s();
        for (uint32_t s = 0; s < timed; ++s) { p.step = 20 + s; b.step(p); }
        return (now_s() - t0) / timed;
    };
    CudaBackendOptions serial_opt;
    serial_opt.prefetch = false;
    const double serial_s =
        time_steps(*make_cuda_backend_ex(asset, opt.network, make_adam_config(opt), serial_opt, opt.seed));
    auto backend = make_cuda_backend_ex(asset, opt.network, make_adam_config(opt), CudaBackendOptions{}, opt.seed);
    const double step_s = time_steps(*backend);
    backend->set_timing(true);
    CudaPhaseTimes acc{};
    const uint32_t phases_n = 20;
    uint64_t draws = 0, drawn_samples = 0; // rays drawn per trained sample (misses redrawn; keep 1 here)
    for (uint32_t s = 0; s < phases_n; ++s) {
        p.step = 200 + s;
        const StepStats st = backend->step(p);
        draws += st.draws;
        drawn_samples += st.samples;
        const CudaPhaseTimes t = backend->phase_times();
        acc.sample += t.sample / phases_n; acc.truth += t.truth / phases_n; acc.encode += t.encode / phases_n;
        acc.mlp += t.mlp / phases_n; acc.grid_backward += t.grid_backward / phases_n;
        acc.reduce_adam += t.reduce_adam / phases_n;
    }
    const double net_ms = acc.encode + acc.mlp + acc.grid_backward + acc.reduce_adam;
    const double full_sps = opt.batch_size / step_s, net_sps = opt.batch_size / (net_ms * 1e-3),
                 mlp_sps = opt.batch_size / (acc.mlp * 1e-3);
    std::printf("full step: %.3f ms, %.4f G samples/s (cut of %zu leaves); without prefetch %.3f ms, %.4f G samples/s\n",
                step_s * 1e3, full_sps * 1e-9, leaves.size(), serial_s * 1e3, opt.batch_size / serial_s * 1e-9);
    std::printf("phases (ms): sample %.3f, truth %.3f, encode %.3f, mlp %.3f, grid backward %.3f, reduce+guard+adam %.3f\n",
                acc.sample, acc.truth, acc.encode, acc.mlp, acc.grid_backward, acc.reduce_adam);
    const double draws_per_sample = double(draws) / double(std::max<uint64_t>(drawn_samples, 1));
    std::printf("sampling: %.3f rays drawn per sample\n", draws_per_sample);
    std::printf("network part (encode+mlp+grid bwd+adam): %.4f G samples/s; fused MLP alone %.4f G samples/s\n",
                net_sps * 1e-9, mlp_sps * 1e-9);

    // 2. Paper-sized training.
    double train_s = -1, train_sps = 0, final_loss = 0;
    uint32_t final_nodes = 0, skipped = 0;
    if (train) {
        TrainOptions t = default_train_options(BackendChoice::cuda);
        t.target_nodes = nodes; // official Chess schedule: 25,249 nodes
        t.steps = steps;
        auto b = make_backend(BackendChoice::cuda, asset, t);
        const TrainResult r = train_asset(asset, t, *b);
        train_s = r.seconds;
        train_sps = r.samples_per_s;
        final_loss = r.log.back().loss.total;
        final_nodes = r.log.back().nodes;
        skipped = r.skipped_steps;
        std::printf("training: %u steps, %u nodes, %.1f s, %.4f G samples/s, final loss %.4f, skipped %u\n", steps,
                    final_nodes, train_s, train_sps * 1e-9, final_loss, skipped);
    }
    if (!json_out.empty()) {
        std::ofstream f(json_out);
        f << "{\n  \"device\": \"" << device << "\",\n  \"asset\": \"" << asset.name << "\",\n  \"triangles\": "
          << asset.triangle_count() << ",\n  \"batch\": " << opt.batch_size << ",\n  \"log2_hash\": "
          << opt.network.log2_hash_size << ",\n  \"step_ms\": " << step_s * 1e3 << ",\n  \"full_step_samples_per_s\": "
          << full_sps << ",\n  \"step_ms_without_prefetch\": " << serial_s * 1e3 << ",\n  \"phase_ms\": {\"sample\": " << acc.sample << ", \"truth\": " << acc.truth
          << ", \"encode\": " << acc.encode << ", \"mlp\": " << acc.mlp << ", \"grid_backward\": " << acc.grid_backward
          << ", \"reduce_adam\": " << acc.reduce_adam << "},\n  \"draws_per_sample\": " << draws_per_sample << ",\n  \"network_samples_per_s\": " << net_sps
          << ",\n  \"mlp_samples_per_s\": " << mlp_sps << ",\n  \"train_steps\": " << steps
          << ",\n  \"train_nodes\": " << final_nodes << ",\n  \"train_seconds\": " << train_s
          << ",\n  \"train_samples_per_s\": " << train_sps << ",\n  \"train_final_loss\": " << final_loss
          << ",\n  \"train_skipped_steps\": " << skipped << "\n}\n";
    }
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "bench_cuda_training: %s\n", e.what());
    return 1;
}
