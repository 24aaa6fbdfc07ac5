// nbvh train SCENE: learns every neural asset of the scene in one model and writes MODEL.nbvh.
// SCENE is a glTF file or "default" (the built-in demo scene, assets/). Which assets are neural follows
// ARCHITECTURE.md: the nodes of a "*_neural" glTF scene, or --neural GLOB; an asset is a unique
// (mesh, material) of those nodes (meshes of several materials are split, engine/neural/asset_table.h),
// and --asset GLOB keeps only the matching assets.
//
// Budget split: one network and one node budget (--nodes) for all assets. Every asset starts as one
// N-BVH leaf; splits are ranked jointly over all assets by the paper's r = 2 log q + log p (rays are
// drawn uniformly over the assets, each asset normalised to the same atlas size), so nodes go where the
// error is, as in the paper's single merged tree.
#include <filesystem>
#include <optional>
#include <string>

#include "app/commands.h"
#include "app/output_path.h"
#include "app/render_args.h"
#include "app/training_scene.h"
#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/neural/model_file.h"
#include "engine/vk/context.h"
#include "trainer/compact_hash.h"
#include "trainer/evaluation.h"
#include "trainer/model_export.h"
#include "trainer/progress_bar.h"
#include "trainer/trainer.h"
#if defined(NBVH_HAVE_CUDA)
#include "trainer/cuda/cuda_backend.h"
#endif

namespace nbvh::app {

namespace {

struct TrainArgs {
    std::string scene;
    std::string neural_glob;
    std::string asset_glob;
    std::string out;
    std::string backend = "auto";
    std::string device = "auto"; // auto | gpu | gpu:N (the CUDA device of Vulkan's GPU N)
    std::string log_csv;
    // Unset (not given on the command line) = the backend's default.
    std::optional<uint32_t> nodes, hash_log2, steps, batch, lods;
    uint32_t threads = 0;
    uint32_t subdivide = 0; // flat midpoint subdivision levels of every mesh (engine/scene/subdivide.h)
    uint64_t seed = 1337;
    bool deterministic = false; // CUDA backend: order-independent gradient sums (trainer/cuda/README.md)
};

// Whether a part has alpha-blended triangles: its visibility target is a stop probability
// (trainer/ground_truth.h), so the check's agreement is with its majority (above 0.5), and its depth
// and normal errors include the surfaces the coverage draws reach behind.
bool blended(const TrainingAsset& asset, const TrainingPart& part) {
    const std::vector<Material>& materials = asset.scene->materials;
    for (uint32_t mat : asset.scene->meshes[part.mesh_index].triangle_material)
        if (mat < materials.size() && materials[mat].alpha_mode == AlphaMode::blend) return true;
    return false;
}

// --device gpu:N: the UUID of the N-th GPU as every other command counts them (Vulkan, PCI bus order,
// nvidia-smi's numbering), so that CUDA trains on it; empty for auto and gpu (CUDA's first device).
std::string training_gpu_uuid(const std::string& device, const std::string& backend) {
    const vk::DeviceSpec spec = vk::parse_device_spec(device);
    if (spec.choice == vk::DeviceChoice::cpu)
        throw Error(
            "--device cpu: the CPU trainer is --backend cpu (--device picks the GPU: auto, gpu or gpu:N)");
    if (spec.gpu_index < 0) return {};
    if (parse_backend(backend) == BackendChoice::cpu)
        throw Error("--device " + device +
                    " picks the GPU that CUDA trains on; it does not go with --backend cpu");
    vk::ContextOptions copt;
    copt.set_device(spec);
    const vk::Context ctx(copt); // throws the one-line error of a GPU number beyond the last
    return ctx.features().device_uuid;
}

void run_train(const TrainArgs& a) {
    use_cuda_device(training_gpu_uuid(a.device, a.backend)); // gpu:N; nothing for auto and gpu
    const BackendChoice backend = resolve_backend(parse_backend(a.backend));
    TrainOptions opt = default_train_options(backend);
    if (a.nodes) opt.target_nodes = *a.nodes;
    if (a.hash_log2) opt.network.log2_hash_size = *a.hash_log2;
    if (a.steps) opt.steps = *a.steps;
    if (a.batch) opt.batch_size = *a.batch;
    if (a.lods) opt.lods = *a.lods;
    opt.seed = a.seed;
    opt.threads = a.threads;
    opt.deterministic = a.deterministic;
    validate(opt);
    // Output paths are checked before the (minutes-long) training, and never replace the input scene.
    const std::string out = a.out.empty()
                                ? (a.scene == "default" ? std::string("default.nbvh")
                                                        : std::filesystem::path(a.scene).stem().string() + ".nbvh")
                                : a.out;
    check_output_path(out, "--out", {a.scene});
    check_output_path(a.log_csv, "--log", {a.scene, out});

    const TrainingScene ts = load_training_scene(a.scene, a.neural_glob, a.asset_glob, a.subdivide);
    const TrainingAsset asset = make_training_asset(ts.scene, ts.meshes);
    if (!a.hash_log2) { // compact default (trainer/compact_hash.h): the grid <= 1/5 of the geometry
        const uint32_t max_log2 = opt.network.log2_hash_size;
        opt.network.log2_hash_size = compact_hash_log2(asset, opt.network, max_log2);
        if (opt.network.log2_hash_size < max_log2)
            log_info("hash 2^%u (compact default: the grid at most 1/5 of the mesh + BLAS it replaces; --hash-log2 %u "
                     "for the backend's maximum)", opt.network.log2_hash_size, max_log2);
    }
    std::unique_ptr<TrainerBackend> be = make_backend(backend, asset, opt);
    const SplitSchedule schedule = make_split_schedule(opt);
    std::string on = backend == BackendChoice::cuda ? "cuda" : "cpu";
#if defined(NBVH_HAVE_CUDA)
    if (backend == BackendChoice::cuda) on += " (" + cuda_device_name() + ")"; // the GPU --device picked
#endif
    log_info(
        "training %s (%u triangles) on %s: %u steps x %u rays, target %u nodes, hash 2^%u, %u LoD(s); %s",
        asset.name.c_str(), asset.triangle_count(), on.c_str(), opt.steps, opt.batch_size, opt.target_nodes,
        opt.network.log2_hash_size, opt.lods, describe(schedule).c_str());

    ProgressBar bar;
    TrainResult result = train_asset(asset, opt, *be, [&](const TrainProgress& p) { bar.update(p); });
    bar.finish();

    if (!a.log_csv.empty()) write_train_log_csv(result.log, a.log_csv);
    // A quick check of every asset at every LoD against the triangles (CPU reference network, fresh rays
    // of the training distribution).
    log_info("check on 2000 fresh rays per asset and LoD: visibility agreement, depth error (of the leaf "
             "segment), normal error");
    for (uint32_t lod = 0; lod < result.tree.lod_count(); ++lod) {
        const TrainingCut cut = cut_of_tree(asset, result.tree, lod);
        for (int32_t p = 0; p < int32_t(asset.parts.size()); ++p) {
            const EvalStats e = evaluate_network(asset, cut, result.weights, 2000, opt.seed, p);
            const TrainingPart& part = asset.parts[size_t(p)];
            log_info("  LoD %u  %-32s %5.1f %%  %.3f  %4.1f deg%s", lod, part.name.c_str(), 100.0 * e.visibility_agreement,
                     e.depth_mae, e.normal_mean_deg, blended(asset, part) ? "  (alpha-blended: agreement with the stop probability above 0.5)" : "");
        }
    }
    const NeuralModel model = make_neural_model(asset, result, opt, a.scene, ts.source_hash);
    save_model(out, model);
    const LossTerms& l = result.log.back().loss;
    log_info("wrote %s: %u nodes, %u leaves, final loss %.4f (vis %.4f, depth %.4f, normal %.4f, albedo %.4f), "
             "%s, %.0f samples/s%s",
             out.c_str(), result.tree.node_count(), result.tree.leaf_count(), l.total, l.visibility, l.depth,
             l.normal, l.albedo, format_duration(result.seconds).c_str(), result.samples_per_s,
             result.skipped_steps ? strfmt(", %u steps skipped", result.skipped_steps).c_str() : "");
}

} // namespace

void add_train_command(CLI::App& app) {
    auto args = std::make_shared<TrainArgs>();
    auto* cmd = app.add_subcommand("train", "learn every neural asset of a scene (one model) and write a .nbvh file");
    cmd->add_option("scene", args->scene, "glTF scene (.gltf/.glb), or 'default' for the built-in demo scene")
        ->required();
    cmd->add_option("--neural", args->neural_glob, "glob of node names to make neural (overrides '*_neural' scenes)");
    cmd->add_option("--asset", args->asset_glob, "train only the neural assets whose name matches this glob");
    cmd->add_option("--out,-o", args->out, "output model (default: SCENE.nbvh in the current directory)");
    cmd->add_option("--backend", args->backend, "cpu, cuda or auto (default: auto = cuda when a GPU is usable)");
    cmd->add_option("--device", args->device,
                    "GPU that CUDA trains on: auto or gpu (CUDA's first device), gpu:N (the N-th GPU in PCI "
                    "order, nvidia-smi's number, as --device of render, view and study)");
    cmd->add_option("--nodes", args->nodes, "target N-BVH node count (CPU default 1000, CUDA 2395)");
    cmd->add_option("--hash-log2", args->hash_log2, "log2 of the hash-table entries per level (default: compact, the largest up to CPU 15 / CUDA 18 whose grid is at most 1/5 of the replaced mesh + BLAS)");
    cmd->add_option("--steps", args->steps, "optimiser steps (CPU default 1000, CUDA 10000)");
    cmd->add_option("--batch", args->batch, "rays per step (CPU default 2048, CUDA 262144)");
    cmd->add_option("--lods", args->lods, "cuts kept as levels of detail (1..8, default 3: render and view trace rays after the first hit on the coarsest)");
    add_subdivide_option(cmd, args->subdivide);
    cmd->add_option("--seed", args->seed, "random seed (network init and rays)");
    cmd->add_option("--threads", args->threads, "CPU backend threads (default: all cores)");
    cmd->add_flag("--deterministic", args->deterministic, "CUDA backend: bit-reproducible steps (slower)");
    cmd->add_option("--log", args->log_csv, "write a CSV log of the losses and node count per step");
    cmd->callback([args] { run_train(*args); });
}

} // namespace nbvh::app
