// One configuration of a study: train a model in-process, decimate the neural meshes to its bytes, and
// from every camera render each variant (every LoD, the LoD switch, the raised leaf budget) and the
// decimated meshes: frame time, image, FLIP beside the noise floor, memory, the equal-time baseline.
// The hybrid renderers serve the whole sweep (the model swapped in by apply()); the decimated scene's
// are built per configuration, for all cameras.
#include "app/study/study_run.h"

#include <future>

#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <map>
#include <memory>
#include <thread>

#include "app/output_path.h"
#include "app/render_args.h"
#include "app/render_measure.h"
#include "app/study/study_cameras.h"
#include "app/study/study_progress.h"
#include "app/study/study_rows.h"
#include "app/training_scene.h"
#include "engine/bvh/scene_accel.h"
#include "engine/core/error.h"
#include "engine/core/exposure.h"
#include "engine/core/flip.h"
#include "engine/core/log.h"
#include "engine/neural/asset_table.h"
#include "engine/render/decimation.h"
#include "engine/render/gpu_memory.h"
#include "engine/render/wavefront.h"
#include "engine/vk/context.h"
#include "trainer/compact_hash.h"
#include "trainer/model_export.h"
#include "trainer/trainer.h"
#if defined(NBVH_HAVE_CUDA)
#include "trainer/cuda/cuda_backend.h"
#endif

namespace nbvh::app::study {

TrainOptions StudyRun::train_options(const Config& c) const {
    TrainOptions opt = default_train_options(backend_);
    opt.target_nodes = c.nodes;
    opt.network.log2_hash_size = c.hash_log2;
    if (o_.steps) opt.steps = *o_.steps;
    if (o_.batch) opt.batch_size = *o_.batch;
    opt.lods = o_.lods;
    opt.seed = o_.train_seed;
    opt.threads = o_.threads;
    validate(opt);
    return opt;
}

void StudyRun::run_config(size_t index, const Config& c) {
    // Train.
    const TrainOptions opt = train_options(c);
    const std::string label =
        strfmt("config %zu/%zu (nodes %u, hash 2^%u)", index + 1, configs_.size(), c.nodes, c.hash_log2);
    progress_.begin(StudyTask::train, double(opt.steps) * opt.batch_size, label + ": training");
    const TrainResult tr = [&] { // the backend (its GPU memory) is gone before the renders
        std::unique_ptr<TrainerBackend> be = make_backend(backend_, *asset_, opt);
        return train_asset(*asset_, opt, *be, [&](const TrainProgress& p) {
            progress_.partial(double(p.step) / double(std::max(1u, p.steps)));
        });
    }();
    // The renderers point at the last configuration's model until their first apply() below swaps the
    // new one in (apply() compares model addresses): the old one stays alive (previous_model_) so that
    // pointer is never dangling, and the new one, allocated while it lives, has another address.
    previous_model_ = std::move(model_);
    model_ = std::make_unique<NeuralModel>(make_neural_model(*asset_, tr, opt, o_.scene, ts_.source_hash));
    const NeuralModel& model = *model_;
    const render::NeuralGpuBytes bytes = render::neural_gpu_bytes(model);
    progress_.end(strfmt("%u nodes, %s, final loss %.4f, %.1f s", tr.tree.node_count(),
                         strfmt("%.2f MiB", double(bytes.total()) / 1048576.0).c_str(),
                         tr.log.back().loss.total, tr.seconds));
    config_json_.push_back({{"config", index},
                            {"nodes_target", c.nodes},
                            {"hash_log2", c.hash_log2},
                            {"nodes", tr.tree.node_count()},
                            {"lod_node_counts", model.lod_node_counts},
                            {"train_seconds", tr.seconds},
                            {"train_steps", opt.steps},
                            {"train_batch", opt.batch_size},
                            {"final_loss", tr.log.back().loss.total},
                            {"skipped_steps", tr.skipped_steps},
                            {"neural_bytes",
                             {{"total", bytes.total()},
                              {"grid", bytes.grid},
                              {"mlp", bytes.mlp},
                              {"mlp_transposed", bytes.mlp_transposed},
                              {"levels", bytes.levels},
                              {"nodes", bytes.nodes},
                              {"node_bounds", bytes.node_bounds},
                              {"occupancy", bytes.occupancy},
                              {"assets", bytes.assets},
                              {"params", bytes.params}}}});

    // The scene as the models see it (their asset table decides which instances are neural): every
    // configuration learns the same assets, so it is bound once; apply() checks each model against it.
    if (!hybrid_scene_) {
        Scene bound = ts_.scene;
        bind_model_to_scene(bound, model, "the study's model");
        hybrid_scene_.emplace(std::move(bound));
    }
    const uint32_t lods = std::max(1u, model.lod_count);
    const std::vector<Variant> variants = variants_of(index, lods);

    // The equal-memory baseline: the neural meshes simplified to the bytes of the LoD-0 model, with its
    // BVHs. CPU work (about a second on the default scene): it runs on a worker thread while camera 0's
    // variants render, and is taken before camera 0's decimated row. The worker only reads ts_.
    struct Decimated {
        render::Decimation dec;
        SceneAccel accel;
        double seconds = 0.0;
    };
    std::future<Decimated> dec_job;
    if (o_.decimation)
        dec_job = std::async(std::launch::async, [this, budget = bytes.total_for_lod(0)] {
            const auto t0 = std::chrono::steady_clock::now();
            Decimated d{render::decimate_to_budget(ts_.scene, ts_.meshes, budget), {}, 0.0};
            d.accel = build_scene_accel(d.dec.scene);
            d.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            return d;
        });
    std::optional<Decimated> decimated; // outlives the renderers below, which keep its scene and BVHs

    // One renderer per image size for every camera (set_camera): building one (scene upload, pipelines)
    // costs about as much as a variant's renders. The hybrid ones serve the whole sweep (the model is
    // swapped in by the rows' apply(): an upload); the decimated scene's are this configuration's.
    RenderOptions ho = image_options(o_.render.spp, o_.render.seed);
    ho.neural.model = &model;
    if (!hybrid_)
        hybrid_ = std::make_unique<WavefrontRenderer>(*ctx_, *hybrid_scene_, accel_, env_, cams_.front().camera, ho);
    if (separate_timing() && !hybrid_timing_) {
        RenderOptions t = timing_options();
        t.neural.model = &model;
        hybrid_timing_ =
            std::make_unique<WavefrontRenderer>(*ctx_, *hybrid_scene_, accel_, env_, cams_.front().camera, t);
    }
    WavefrontRenderer& hybrid = *hybrid_;
    WavefrontRenderer* timing = hybrid_timing_.get();
    RenderOptions dopt = image_options(o_.render.spp, o_.render.seed);
    dopt.neural.classical = true;
    std::unique_ptr<WavefrontRenderer> dr, dtiming; // built when the decimation is done
    auto take_decimation = [&](const Camera& camera) {
        decimated.emplace(dec_job.get());
        config_json_.back()["decimation_seconds"] = decimated->seconds;
        const render::Decimation& d = decimated->dec;
        dr = std::make_unique<WavefrontRenderer>(*ctx_, d.scene, decimated->accel, env_, camera, dopt);
        if (separate_timing()) {
            RenderOptions t = timing_options();
            t.neural.classical = true;
            dtiming = std::make_unique<WavefrontRenderer>(*ctx_, d.scene, decimated->accel, env_, camera, t);
        }
    };
    for (size_t ci = 0; ci < cams_.size(); ++ci) {
        CameraSide& cam = cams_[ci];
        for (WavefrontRenderer* r : {&hybrid, timing, dr.get(), dtiming.get()})
            if (r) r->set_camera(cam.camera);
        Image base_px;
        for (const Variant& v : variants) {
            RenderOptions vo = ho;
            vo.neural.lod = uint32_t(v.lod);
            vo.neural.secondary_lod = v.secondary;
            vo.neural.max_rounds = v.max_leaves;
            // The cap row raises every ray's budget (its image change is what the default budgets cost).
            if (v.kind == "cap") vo.neural.max_rounds_secondary = vo.neural.max_rounds_shadow = 0;
            const std::string what =
                v.kind == "switch" ? strfmt("LoD %d, then %d after the first hit", v.lod, v.secondary)
                : v.kind == "cap"  ? strfmt("LoD %d, <= %u leaves per ray", v.lod, v.max_leaves)
                                   : strfmt("LoD %d", v.lod);
            progress_.begin(StudyTask::render, variant_work(v.equal_time),
                            strfmt("%s, camera %zu: %s", label.c_str(), ci, what.c_str()));
            StudyRow row;
            row.config = int(index);
            row.variant = v.kind;
            row.camera = int(ci);
            row.nodes_target = c.nodes;
            row.hash_log2 = c.hash_log2;
            row.lods = lods;
            row.lod = v.lod;
            row.secondary_lod = v.secondary;
            row.max_leaves = v.max_leaves;
            row.nodes = model.lod_node_counts.empty() ? 0 : model.lod_node_counts[size_t(v.lod)];
            row.memory_bytes = bytes.total_for_lod(uint32_t(v.lod));
            row.resident_bytes = bytes.total();
            row.compression = double(source_bytes_) / double(row.memory_bytes);
            row.train_seconds = tr.seconds;
            row.final_loss = tr.log.back().loss.total;
            row.frame_ms = time_frame(hybrid, timing, vo);
            row.classical_frame_ms = cam.kept.classical_ms;
            row.ratio_to_classical = row.frame_ms / cam.kept.classical_ms;
            const render::RenderResult res = render_with(hybrid, vo);
            const Image px = as_png_pixels(res.image, cam.kept.exposure);
            row.queries_per_ray = res.stats.neural_queries_per_ray();
            row.leaf_cap_fraction = res.stats.rays_total() ? double(res.stats.neural_leaf_cap_rays) /
                                                                 double(res.stats.rays_total())
                                                           : 0.0;
            kernel_ = res.stats.neural_path;
            row.flip = cam.ref_flip->compare(px).mean;
            row.noise_floor = cam.kept.noise_floor;
            row.flip_same_seed = cam.floor_flip->compare(px).mean;
            if (v.kind == "lod" && v.lod == 0) base_px = px;
            if (v.kind == "cap" && base_px.width) row.flip_vs_base_cap = flip_ldr(base_px, px).mean;
            if (v.equal_time)
                row.equal_time_flip = equal_time(cam, row.ratio_to_classical, &row.equal_time_spp);
            mark_floor(row);
            if (o_.save_images && index == 0 && ci == 0 && v.kind == "lod" && v.lod == 0)
                save("hybrid_cam0.png", res.image, cam.kept.exposure);
            rows_.push_back(row);
            progress_.end(strfmt("FLIP %.4f (floor %.4f%s), %.2fx classical, %.2f MiB", row.flip,
                                 row.noise_floor, row.within_2x_floor ? ", within 2x floor" : "",
                                 row.ratio_to_classical, double(row.memory_bytes) / 1048576.0));
        }
        if (o_.decimation) {
            if (!decimated) take_decimation(cam.camera);
            const render::Decimation* dec = &decimated->dec;
            progress_.begin(StudyTask::render, pixel_samples(o_.render.spp) + timing_work(),
                            strfmt("%s, camera %zu: decimated to %llu triangles", label.c_str(), ci,
                                   (unsigned long long)dec->triangles));
            StudyRow row;
            row.config = int(index);
            row.variant = "decimated";
            row.camera = int(ci);
            row.nodes_target = c.nodes;
            row.hash_log2 = c.hash_log2;
            row.lods = lods;
            row.memory_bytes = row.resident_bytes = dec->bytes;
            row.triangles = dec->triangles;
            row.compression = double(source_bytes_) / double(dec->bytes);
            row.decimation_sloppy = dec->sloppy;
            row.frame_ms = time_frame(*dr, dtiming.get(), dopt);
            row.classical_frame_ms = cam.kept.classical_ms;
            row.ratio_to_classical = row.frame_ms / cam.kept.classical_ms;
            const render::RenderResult res = render_with(*dr, dopt);
            const Image px = as_png_pixels(res.image, cam.kept.exposure);
            row.flip = cam.ref_flip->compare(px).mean;
            row.noise_floor = cam.kept.noise_floor;
            row.flip_same_seed = cam.floor_flip->compare(px).mean;
            mark_floor(row);
            if (o_.save_images && index == 0 && ci == 0)
                save("decimated_cam0.png", res.image, cam.kept.exposure);
            rows_.push_back(row);
            progress_.end(strfmt("FLIP %.4f (floor %.4f), %.2f MiB (%+.1f %% of the model's)", row.flip,
                                 row.noise_floor, double(dec->bytes) / 1048576.0,
                                 100.0 * dec->relative_error()));
        }
    }
}

} // namespace nbvh::app::study
