// Benchmark: CPU training throughput (trained samples per second) and the accuracy the CPU defaults
// reach. Not a test (no timing assertions): run it by hand or from scripts and commit the figures.
//
//   bench_cpu_training [--scene PATH|default] [--glob GLOB] [--steps N] [--batch N] [--nodes N]
//                      [--hash-log2 K] [--threads T] [--json FILE] [--md FILE]
//
// Default: the Stanford Bunny from ../shared/scenes with the CPU defaults of `nbvh train`.
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <thread>

#include "assets/default_scene.h"
#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/scene/gltf_loader.h"
#include "tests/support/test_support.h"
#include "trainer/evaluation.h"
#include "trainer/progress_bar.h"
#include "trainer/trainer.h"

using namespace nbvh;

int main(int argc, char** argv) try {
    std::string scene_path, glob = "*", json_out, md_out;
    TrainOptions opt = default_train_options(BackendChoice::cpu);
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string k = argv[i], v = argv[i + 1];
        if (k == "--scene") scene_path = v;
        else if (k == "--glob") glob = v;
        else if (k == "--steps") opt.steps = uint32_t(std::stoul(v));
        else if (k == "--batch") opt.batch_size = uint32_t(std::stoul(v));
        else if (k == "--nodes") opt.target_nodes = uint32_t(std::stoul(v));
        else if (k == "--hash-log2") opt.network.log2_hash_size = uint32_t(std::stoul(v));
        else if (k == "--threads") opt.threads = uint32_t(std::stoul(v));
        else if (k == "--json") json_out = v;
        else if (k == "--md") md_out = v;
        else throw Error("unknown option " + k);
    }
    if (scene_path.empty()) {
        if (!test::shared_dir()) throw Error("../shared/scenes not found; pass --scene");
        scene_path = (test::scenes_dir() / "stanford_bunny" / "stanford_bunny.glb").string();
    }
    Scene scene;
    if (scene_path == "default") {
        scene = assets::make_default_scene(); // its neural asset is flagged by the generator
    } else {
        SceneLoadOptions lo;
        lo.neural_glob = glob;
        scene = load_gltf(scene_path, lo);
    }
    const TrainingAsset asset = make_training_asset(scene, pick_neural_mesh(scene));
    const unsigned threads = opt.threads ? opt.threads : std::max(1u, std::thread::hardware_concurrency());

    auto backend = make_backend(BackendChoice::cpu, asset, opt);
    ProgressBar bar;
    const TrainResult r = train_asset(asset, opt, *backend, [&](const TrainProgress& p) { bar.update(p); });
    bar.finish();
    const EvalStats e = evaluate_network(asset, cut_of_tree(asset, r.tree, 0), r.weights, 20000, 99);

    const LossTerms& first = r.log.front().loss;
    LossTerms last{};
    const size_t tail = std::min<size_t>(50, r.log.size());
    for (size_t i = r.log.size() - tail; i < r.log.size(); ++i) {
        last.visibility += r.log[i].loss.visibility / double(tail);
        last.depth += r.log[i].loss.depth / double(tail);
        last.normal += r.log[i].loss.normal / double(tail);
        last.albedo += r.log[i].loss.albedo / double(tail);
        last.total += r.log[i].loss.total / double(tail);
    }
    const std::string summary = strfmt(
        "asset %s (%u triangles), %u threads, %u steps x %u rays, hash 2^%u, %u nodes: %.1f s, %.0f samples/s; "
        "loss %.4f -> %.4f (vis %.4f -> %.4f, depth %.4f -> %.4f, normal %.4f -> %.4f, albedo %.4f -> %.4f); "
        "eval on %u fresh rays: visibility agreement %.2f%%, depth MAE %.4f (p90 %.4f) of the segment, "
        "%.5f of the asset diagonal; normal %.1f deg; albedo MAE %.4f; skipped steps %u",
        asset.name.c_str(), asset.triangle_count(), threads, opt.steps, opt.batch_size, opt.network.log2_hash_size,
        r.tree.node_count(), r.seconds, r.samples_per_s, first.total, last.total, first.visibility, last.visibility,
        first.depth, last.depth, first.normal, last.normal, first.albedo, last.albedo, e.rays,
        100.0 * e.visibility_agreement, e.depth_mae, e.depth_p90, e.depth_mae_rel_asset, e.normal_mean_deg,
        e.albedo_mae, r.skipped_steps);
    std::printf("%s\n", summary.c_str());
    if (!json_out.empty()) {
        std::ofstream f(json_out);
        f << strfmt("{\n  \"asset\": \"%s\",\n  \"triangles\": %u,\n  \"threads\": %u,\n  \"steps\": %u,\n"
                    "  \"batch\": %u,\n  \"hash_log2\": %u,\n  \"nodes\": %u,\n  \"seconds\": %.2f,\n"
                    "  \"samples_per_s\": %.0f,\n  \"loss_first\": %.5f,\n  \"loss_last50\": %.5f,\n"
                    "  \"visibility_agreement\": %.5f,\n  \"depth_mae_segment\": %.5f,\n  \"depth_p90_segment\": %.5f,\n"
                    "  \"depth_mae_asset_diagonal\": %.6f,\n  \"normal_mean_deg\": %.2f,\n  \"albedo_mae\": %.5f,\n"
                    "  \"skipped_steps\": %u\n}\n",
                    asset.name.c_str(), asset.triangle_count(), threads, opt.steps, opt.batch_size,
                    opt.network.log2_hash_size, r.tree.node_count(), r.seconds, r.samples_per_s, first.total,
                    last.total, e.visibility_agreement, e.depth_mae, e.depth_p90, e.depth_mae_rel_asset,
                    e.normal_mean_deg, e.albedo_mae, r.skipped_steps);
    }
    if (!md_out.empty()) {
        std::ofstream f(md_out, std::ios::app);
        f << "- " << summary << "\n";
    }
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "bench_cpu_training: %s\n", e.what());
    return 1;
}
