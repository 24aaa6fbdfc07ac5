// The order of work: the classical side of every camera first (converged reference, the noise floor at
// the compared spp, the classical frame time), then per configuration: train, decimate to its bytes,
// and per camera every variant of the model (frame time, image, FLIP), the decimated meshes, and the
// classical renders at equal time (cached per spp). Renderers are built once per camera and model and
// switched between variants with WavefrontRenderer::apply (uploads, no new pipelines).
#include "app/study/study_runner.h"

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

namespace nbvh::app {
namespace {

namespace fs = std::filesystem;
using render::RenderOptions;
using render::WavefrontRenderer;

// The reference's seed: any seed other than the compared images' (their noise must be independent).
constexpr uint32_t REFERENCE_SEED_OFFSET = 1000003;

std::string utc_now() {
    const std::time_t t = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&t, &tm);
    char buf[32];
    std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buf;
}

struct Config {
    uint32_t nodes = 0, hash_log2 = 0;
};

// Everything of one camera that every configuration compares against.
struct CameraSide {
    Camera camera;
    float exposure = 0.0f;  // stops of every PNG of this camera (the reference's auto exposure)
    // The reference (ref_spp) and the classical image (spp, compared seed) as PNG pixels, prepared once
    // for the FLIPs of every row (FlipReference: the same figures as flip_ldr, half the filtering).
    std::optional<FlipReference> ref_flip, floor_flip;
    double noise_floor = 0.0, classical_ms = 0.0;
    std::unique_ptr<WavefrontRenderer> classical; // image size: reference, floor, equal-time renders
    std::map<uint32_t, double> equal_time_flip;   // classical spp -> FLIP vs the reference
    // Samples of the compared seed in `classical`'s film (the floor render, then equal-time extensions);
    // 0 when the film holds something else.
    uint32_t film_spp = 0;
};

class StudyRun {
  public:
    explicit StudyRun(const StudyOptions& o) : o_(o), progress_(stderr) {}
    void run();

  private:
    RenderOptions image_options(uint32_t spp, uint32_t seed) const {
        RenderOptions r = o_.render;
        r.spp = spp;
        r.seed = seed;
        r.neural.path = neural_path_;
        return r;
    }
    RenderOptions timing_options() const {
        RenderOptions r = image_options(o_.time_spp, o_.render.seed);
        if (time_width_) r.width = time_width_, r.height = time_height_;
        return r;
    }
    bool separate_timing() const {
        return time_width_ && (time_width_ != o_.render.width || time_height_ != o_.render.height);
    }
    double pixel_samples(uint32_t spp) const { return double(o_.render.width) * o_.render.height * spp; }
    // A hybrid row: its image (counted 1.5x a classical one), its frames, and the equal-time classical image
    // (about the hybrid's time; cached, so often free).
    double variant_work(bool equal_time) const {
        return (1.5 + (equal_time ? 1.0 : 0.0)) * pixel_samples(o_.render.spp) + timing_work();
    }
    // The rows of one configuration (study_rows.h kinds). Equal-time renders: LoD 0 and the LoD switch
    // (what a user renders by default or to save time); the raised leaf budget: the middle configuration.
    struct Variant {
        std::string kind;
        int lod, secondary;
        uint32_t max_leaves;
        bool equal_time;
    };
    std::vector<Variant> variants_of(size_t config, uint32_t lods) const {
        std::vector<Variant> v;
        const uint32_t cap = o_.render.neural.max_rounds;
        for (uint32_t l = 0; l < lods; ++l)
            v.push_back({"lod", int(l), int(l), cap, o_.equal_time && l == 0});
        if (lods > 1) v.push_back({"switch", 0, int(lods - 1), cap, o_.equal_time});
        if (o_.cap_study && o_.cap_study != cap && config == configs_.size() / 2)
            v.push_back({"cap", 0, 0, o_.cap_study, false});
        return v;
    }
    double timing_work() const {
        const RenderOptions t = timing_options();
        return double(t.width) * t.height * t.spp * (o_.repeat + 1);
    }
    render::RenderResult render_with(WavefrontRenderer& r, const RenderOptions& opt);
    void save(const char* name, const Image& linear, float exposure) const;
    double time_frame(WavefrontRenderer& image_renderer, WavefrontRenderer* timing_renderer,
                      RenderOptions opt);
    void plan();
    void classical_side();
    void run_config(size_t index, const Config& c);
    double equal_time(CameraSide& cam, double ratio, uint32_t* spp_out);
    void write_results() const;

    const StudyOptions& o_;
    StudyProgress progress_;
    render::NeuralPath neural_path_ = render::NeuralPath::automatic;
    uint32_t time_width_ = 0, time_height_ = 0;
    BackendChoice backend_ = BackendChoice::cpu;
    std::optional<float> fixed_exposure_;
    std::unique_ptr<vk::Context> ctx_;
    TrainingScene ts_;
    std::unique_ptr<TrainingAsset> asset_;
    SceneAccel accel_;
    Environment env_;
    std::vector<CameraSide> cams_;
    std::vector<Config> configs_;
    uint64_t source_bytes_ = 0, source_triangles_ = 0;
    std::string device_, driver_, train_device_, kernel_;
    std::vector<StudyRow> rows_;
    nlohmann::json config_json_ = nlohmann::json::array();
    std::string started_, stop_reason_;
    size_t configs_done_ = 0;
};

render::RenderResult StudyRun::render_with(WavefrontRenderer& r, const RenderOptions& opt) {
    NBVH_CHECK(r.apply(opt));
    return r.render();
}

// A PNG as `nbvh render` writes it, at the camera's exposure.
void StudyRun::save(const char* name, const Image& linear, float exposure) const {
    PngEncode enc;
    enc.tone_map = ToneMap::aces;
    enc.exposure = exposure;
    save_png((fs::path(o_.out_dir) / name).string(), linear, enc);
}

// GPU ms of one frame (time_spp samples per pixel): median of `repeat` after a warm-up, at the timing
// resolution (its own renderer when that differs from the image size).
double StudyRun::time_frame(WavefrontRenderer& image_renderer, WavefrontRenderer* timing_renderer,
                            RenderOptions opt) {
    WavefrontRenderer& r = timing_renderer ? *timing_renderer : image_renderer;
    opt.spp = o_.time_spp;
    opt.seed = o_.render.seed;
    if (timing_renderer) opt.width = time_width_, opt.height = time_height_;
    NBVH_CHECK(r.apply(opt));
    return median_render_stats(r, o_.repeat).gpu_ms;
}

void StudyRun::plan() {
    const double cams = double(cams_.size());
    for (size_t c = 0; c < cams_.size(); ++c) {
        progress_.plan(StudyTask::render,
                       pixel_samples(o_.ref_spp) + pixel_samples(o_.render.spp) + timing_work());
    }
    const TrainOptions d = default_train_options(backend_);
    const double samples = double(o_.steps.value_or(d.steps)) * o_.batch.value_or(d.batch_size);
    for (size_t i = 0; i < configs_.size(); ++i) {
        progress_.plan(StudyTask::train, samples);
        for (size_t c = 0; c < cams; ++c) {
            for (const Variant& v : variants_of(i, o_.lods))
                progress_.plan(StudyTask::render, variant_work(v.equal_time));
            if (o_.decimation)
                progress_.plan(StudyTask::render, pixel_samples(o_.render.spp) + timing_work());
        }
    }
}

void StudyRun::classical_side() {
    const Scene& scene = ts_.scene;
    for (size_t c = 0; c < cams_.size(); ++c) {
        CameraSide& cam = cams_[c];
        progress_.begin(StudyTask::render,
                        pixel_samples(o_.ref_spp) + pixel_samples(o_.render.spp) + timing_work(),
                        strfmt("camera %zu: classical reference (%u spp), noise floor (%u spp)", c,
                               o_.ref_spp, o_.render.spp));
        RenderOptions ref = image_options(o_.ref_spp, o_.render.seed + REFERENCE_SEED_OFFSET);
        ref.neural.classical = true;
        render::validate(ref.neural, scene);
        cam.classical = std::make_unique<WavefrontRenderer>(*ctx_, scene, accel_, env_, cam.camera, ref);
        render::RenderResult r = cam.classical->render();
        device_ = r.stats.device, driver_ = r.stats.driver;
        cam.exposure = fixed_exposure_ ? *fixed_exposure_ : auto_exposure(r.image).stops;
        const Image ref_px = as_png_pixels(r.image, cam.exposure);
        if (o_.save_images && c == 0) save("reference_cam0.png", r.image, cam.exposure);
        RenderOptions same = image_options(o_.render.spp, o_.render.seed);
        same.neural.classical = true;
        const Image floor_px = as_png_pixels(render_with(*cam.classical, same).image, cam.exposure);
        cam.film_spp = o_.render.spp;
        cam.ref_flip.emplace(ref_px);
        cam.floor_flip.emplace(floor_px);
        cam.noise_floor = cam.ref_flip->compare(floor_px).mean;
        std::unique_ptr<WavefrontRenderer> timing;
        if (separate_timing()) {
            RenderOptions t = timing_options();
            t.neural.classical = true;
            timing = std::make_unique<WavefrontRenderer>(*ctx_, scene, accel_, env_, cam.camera, t);
        }
        cam.classical_ms = time_frame(*cam.classical, timing.get(), same);
        cam.equal_time_flip[o_.render.spp] = cam.noise_floor;

        StudyRow row;
        row.variant = "classical";
        row.camera = int(c);
        row.memory_bytes = source_bytes_;
        row.triangles = source_triangles_;
        row.compression = 1.0;
        row.frame_ms = row.classical_frame_ms = cam.classical_ms;
        row.ratio_to_classical = 1.0;
        row.flip = row.noise_floor = cam.noise_floor;
        row.flip_same_seed = 0.0;
        mark_floor(row);
        row.equal_time_spp = o_.render.spp;
        row.equal_time_flip = cam.noise_floor;
        rows_.push_back(row);
        progress_.end(strfmt("noise floor %.4f, classical %.3f ms/frame (%u spp), exposure %+.2f stops",
                             cam.noise_floor, cam.classical_ms, o_.time_spp, cam.exposure));
    }
}

// FLIP of a classical render of `cam` in the time the hybrid needs (ratio x the compared spp; rounded to
// eighths of it, so nearby ratios share one render). The equal-time images of a camera are prefixes of
// one sample sequence (the compared seed, samples 0..spp-1, the floor render's first `spp`), so the film
// left by the floor render is extended eighth by eighth up to the request, caching the FLIP of every
// eighth on the way: a sweep renders each camera's classical samples once instead of once per distinct
// spp. A request below the film (or a film that holds something else) is rendered anew.
double StudyRun::equal_time(CameraSide& cam, double ratio, uint32_t* spp_out) {
    const uint32_t base = o_.render.spp;
    auto spp_of = [&](uint32_t eighths) { return std::max(1u, uint32_t((uint64_t(base) * eighths + 4) / 8)); };
    const uint32_t eighths = uint32_t(std::max(1.0, std::round(8.0 * ratio)));
    const uint32_t spp = spp_of(eighths);
    *spp_out = spp;
    if (auto it = cam.equal_time_flip.find(spp); it != cam.equal_time_flip.end()) return it->second;
    auto flip_of = [&](const Image& linear) { return cam.ref_flip->compare(as_png_pixels(linear, cam.exposure)).mean; };
    const bool extend = cam.film_spp > 0 && cam.film_spp < spp && cam.classical->accumulated_samples() == cam.film_spp;
    if (!extend) {
        RenderOptions opt = image_options(spp, o_.render.seed);
        opt.neural.classical = true;
        cam.equal_time_flip[spp] = flip_of(render_with(*cam.classical, opt).image);
        cam.film_spp = spp;
        return cam.equal_time_flip[spp];
    }
    for (uint32_t e = 1; cam.film_spp < spp; ++e) {
        const uint32_t next = spp_of(e);
        if (next <= cam.film_spp) continue;
        const Image mean = cam.classical->render_progressive(next - cam.film_spp).image;
        cam.film_spp = next;
        if (!cam.equal_time_flip.count(next)) cam.equal_time_flip[next] = flip_of(mean);
    }
    return cam.equal_time_flip.at(spp);
}

void StudyRun::run_config(size_t index, const Config& c) {
    // Train.
    TrainOptions opt = default_train_options(backend_);
    opt.target_nodes = c.nodes;
    opt.network.log2_hash_size = c.hash_log2;
    if (o_.steps) opt.steps = *o_.steps;
    if (o_.batch) opt.batch_size = *o_.batch;
    opt.lods = o_.lods;
    opt.seed = o_.train_seed;
    opt.threads = o_.threads;
    validate(opt);
    const std::string label =
        strfmt("config %zu/%zu (nodes %u, hash 2^%u)", index + 1, configs_.size(), c.nodes, c.hash_log2);
    progress_.begin(StudyTask::train, double(opt.steps) * opt.batch_size, label + ": training");
    const TrainResult tr = [&] { // the backend (its GPU memory) is gone before the renders
        std::unique_ptr<TrainerBackend> be = make_backend(backend_, *asset_, opt);
        return train_asset(*asset_, opt, *be, [&](const TrainProgress& p) {
            progress_.partial(double(p.step) / double(std::max(1u, p.steps)));
        });
    }();
    const NeuralModel model = make_neural_model(*asset_, tr, opt, o_.scene, ts_.source_hash);
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
                              {"assets", bytes.assets},
                              {"params", bytes.params}}}});

    // The scene as the model sees it (its asset table decides which instances are neural).
    Scene hybrid_scene = ts_.scene;
    bind_model_to_scene(hybrid_scene, model, "the study's model");
    const uint32_t lods = std::max(1u, model.lod_count);
    const std::vector<Variant> variants = variants_of(index, lods);

    // The equal-memory baseline: the neural meshes simplified to the bytes of the LoD-0 model.
    std::optional<render::Decimation> dec;
    std::optional<SceneAccel> dec_accel;
    if (o_.decimation) {
        dec = render::decimate_to_budget(ts_.scene, ts_.meshes, bytes.total_for_lod(0));
        dec_accel = build_scene_accel(dec->scene);
    }

    // One renderer per image size for every camera (set_camera), for the model and for the decimated
    // scene: building one (scene upload, pipelines) costs about as much as a variant's renders.
    RenderOptions ho = image_options(o_.render.spp, o_.render.seed);
    ho.neural.model = &model;
    WavefrontRenderer hybrid(*ctx_, hybrid_scene, accel_, env_, cams_.front().camera, ho);
    std::unique_ptr<WavefrontRenderer> timing;
    if (separate_timing()) {
        RenderOptions t = timing_options();
        t.neural.model = &model;
        timing = std::make_unique<WavefrontRenderer>(*ctx_, hybrid_scene, accel_, env_, cams_.front().camera, t);
    }
    RenderOptions dopt = image_options(o_.render.spp, o_.render.seed);
    dopt.neural.classical = true;
    std::unique_ptr<WavefrontRenderer> dr, dtiming;
    if (dec) {
        dr = std::make_unique<WavefrontRenderer>(*ctx_, dec->scene, *dec_accel, env_, cams_.front().camera, dopt);
        if (separate_timing()) {
            RenderOptions t = timing_options();
            t.neural.classical = true;
            dtiming = std::make_unique<WavefrontRenderer>(*ctx_, dec->scene, *dec_accel, env_, cams_.front().camera, t);
        }
    }
    for (size_t ci = 0; ci < cams_.size(); ++ci) {
        CameraSide& cam = cams_[ci];
        for (WavefrontRenderer* r : {&hybrid, timing.get(), dr.get(), dtiming.get()})
            if (r) r->set_camera(cam.camera);
        Image base_px;
        for (const Variant& v : variants) {
            RenderOptions vo = ho;
            vo.neural.lod = uint32_t(v.lod);
            vo.neural.secondary_lod = v.secondary;
            vo.neural.max_rounds = v.max_leaves;
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
            row.frame_ms = time_frame(hybrid, timing.get(), vo);
            row.classical_frame_ms = cam.classical_ms;
            row.ratio_to_classical = row.frame_ms / cam.classical_ms;
            const render::RenderResult res = render_with(hybrid, vo);
            const Image px = as_png_pixels(res.image, cam.exposure);
            row.queries_per_ray = res.stats.neural_queries_per_ray();
            row.leaf_cap_fraction = res.stats.rays_total() ? double(res.stats.neural_leaf_cap_rays) /
                                                                 double(res.stats.rays_total())
                                                           : 0.0;
            kernel_ = res.stats.neural_path;
            row.flip = cam.ref_flip->compare(px).mean;
            row.noise_floor = cam.noise_floor;
            row.flip_same_seed = cam.floor_flip->compare(px).mean;
            if (v.kind == "lod" && v.lod == 0) base_px = px;
            if (v.kind == "cap" && base_px.width) row.flip_vs_base_cap = flip_ldr(base_px, px).mean;
            if (v.equal_time)
                row.equal_time_flip = equal_time(cam, row.ratio_to_classical, &row.equal_time_spp);
            mark_floor(row);
            if (o_.save_images && index == 0 && ci == 0 && v.kind == "lod" && v.lod == 0)
                save("hybrid_cam0.png", res.image, cam.exposure);
            rows_.push_back(row);
            progress_.end(strfmt("FLIP %.4f (floor %.4f%s), %.2fx classical, %.2f MiB", row.flip,
                                 row.noise_floor, row.within_2x_floor ? ", within 2x floor" : "",
                                 row.ratio_to_classical, double(row.memory_bytes) / 1048576.0));
        }
        if (dec) {
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
            row.classical_frame_ms = cam.classical_ms;
            row.ratio_to_classical = row.frame_ms / cam.classical_ms;
            const render::RenderResult res = render_with(*dr, dopt);
            const Image px = as_png_pixels(res.image, cam.exposure);
            row.flip = cam.ref_flip->compare(px).mean;
            row.noise_floor = cam.noise_floor;
            row.flip_same_seed = cam.floor_flip->compare(px).mean;
            mark_floor(row);
            if (o_.save_images && index == 0 && ci == 0) save("decimated_cam0.png", res.image, cam.exposure);
            rows_.push_back(row);
            progress_.end(strfmt("FLIP %.4f (floor %.4f), %.2f MiB (%+.1f %% of the model's)", row.flip,
                                 row.noise_floor, double(dec->bytes) / 1048576.0,
                                 100.0 * dec->relative_error()));
        }
    }
}

void StudyRun::write_results() const {
    std::vector<StudyRow> all = rows_;
    const std::vector<StudyRow> means = mean_over_cameras(rows_);
    all.insert(all.end(), means.begin(), means.end());
    write_text_atomically((fs::path(o_.out_dir) / "study.csv").string(), study_csv(all, o_.scene));
    nlohmann::json cams = nlohmann::json::array();
    for (size_t c = 0; c < cams_.size(); ++c)
        cams.push_back({{"camera", c},
                        {"view", camera_string(cams_[c].camera)},
                        {"exposure_stops", cams_[c].exposure},
                        {"noise_floor", cams_[c].noise_floor},
                        {"classical_frame_ms", cams_[c].classical_ms}});
    nlohmann::json rows = nlohmann::json::array(), mean_rows = nlohmann::json::array();
    for (const StudyRow& r : rows_) rows.push_back(row_json(r));
    for (const StudyRow& r : means) mean_rows.push_back(row_json(r));
    const RenderOptions t = timing_options();
    nlohmann::json j = {
        {"study", "nbvh study (issue 11)"},
        {"scene", o_.scene},
        {"command_line", o_.command_line},
        {"commit", o_.commit},
        {"started_utc", started_},
        {"complete", configs_done_ == configs_.size()},
        {"configs_done", configs_done_},
        {"configs_planned", configs_.size()},
        {"stop_reason", stop_reason_},
        {"written_utc", utc_now()},
        {"device", device_},
        {"driver", driver_},
        {"training_backend", backend_ == BackendChoice::cuda ? "cuda" : "cpu"},
        {"training_device", train_device_},
        {"vulkan_validation", ctx_ && ctx_->validation_enabled()},
        {"neural_meshes",
         {{"count", ts_.meshes.size()}, {"triangles", source_triangles_}, {"gpu_bytes", source_bytes_}}},
        {"settings",
         {{"width", o_.render.width},
          {"height", o_.render.height},
          {"spp", o_.render.spp},
          {"ref_spp", o_.ref_spp},
          {"seed", o_.render.seed},
          {"reference_seed", o_.render.seed + REFERENCE_SEED_OFFSET},
          {"max_depth", o_.render.max_depth},
          {"time_spp", o_.time_spp},
          {"time_width", t.width},
          {"time_height", t.height},
          {"repeat", o_.repeat},
          {"max_leaves", o_.render.neural.max_rounds},
          {"cap_study", o_.cap_study},
          {"leaves_per_round", o_.render.neural.leaves_per_round},
          {"neural_path", render::neural_path_name(neural_path_)},
          {"neural_kernel", kernel_},
          {"lods", o_.lods},
          {"exposure", o_.exposure},
          {"neural_scratch_bytes_per_ray",
           render::neural_scratch_bytes_per_ray(o_.render.neural.leaves_per_round)}}},
        {"flip_metric",
         "LDR-FLIP (ppd 67.02) of ACES-tone-mapped 8-bit sRGB images, one exposure per camera"},
        {"cameras", cams},
        {"configs", config_json_},
        {"rows", rows},
        {"mean_rows", mean_rows}};
    write_text_atomically((fs::path(o_.out_dir) / "study.json").string(), j.dump(1) + "\n");
}

void StudyRun::run() {
    started_ = utc_now();
    // Cheap checks first: options, output folder, scene, environment, cameras.
    if (o_.out_dir.empty()) throw Error("--out DIR is required");
    if (fs::exists(o_.out_dir) && !fs::is_directory(o_.out_dir))
        throw Error(strfmt("--out '%s' is a file, not a folder", o_.out_dir.c_str()));
    if (!fs::exists(fs::path(o_.out_dir).parent_path().empty() ? fs::path(".")
                                                               : fs::path(o_.out_dir).parent_path()))
        throw Error(strfmt("--out '%s': its parent folder does not exist", o_.out_dir.c_str()));
    if (o_.lods == 0 || o_.lods > NBVH_MAX_LODS)
        throw Error(strfmt("--lods must be in [1, %u]", NBVH_MAX_LODS));
    if (o_.ref_spp < o_.render.spp)
        throw Error("--ref-spp must be at least --spp (the reference must be converged)");
    if ((o_.time_width == 0) != (o_.time_height == 0))
        throw Error("--time-width and --time-height go together");
    time_width_ = o_.time_width;
    time_height_ = o_.time_height;
    neural_path_ = render::parse_neural_path(o_.neural_path);
    fixed_exposure_ = parse_exposure(o_.exposure);
    backend_ = resolve_backend(parse_backend(o_.backend));
    ts_ = load_training_scene(o_.scene, o_.neural_glob, o_.asset_glob);
    env_ = choose_environment(ts_.scene, o_.env);
    if (o_.env_rotation) env_.rotation = *o_.env_rotation * 3.14159265358979f / 180.0f;
    cams_.resize(0);
    for (const Camera& c : study_cameras(ts_.scene, o_.cameras, o_.camera_count,
                                         float(o_.render.width) / float(o_.render.height)))
        cams_.push_back(CameraSide{c});
    fs::create_directories(o_.out_dir);

    asset_ = std::make_unique<TrainingAsset>(make_training_asset(ts_.scene, ts_.meshes));
    const TrainOptions defaults = default_train_options(backend_);
    const uint32_t default_hash =
        compact_hash_log2(*asset_, defaults.network, defaults.network.log2_hash_size);
    for (uint32_t n : o_.nodes.empty() ? std::vector<uint32_t>{defaults.target_nodes} : o_.nodes)
        for (uint32_t h : o_.hash_log2.empty() ? std::vector<uint32_t>{default_hash} : o_.hash_log2)
            configs_.push_back({n, h});
    for (const Config& c : configs_) { // validate every configuration before the first training
        TrainOptions t = defaults;
        t.target_nodes = c.nodes;
        t.network.log2_hash_size = c.hash_log2;
        t.lods = o_.lods;
        if (o_.steps) t.steps = *o_.steps;
        if (o_.batch) t.batch_size = *o_.batch;
        validate(t);
    }
    for (uint32_t m : ts_.meshes) {
        source_triangles_ += ts_.scene.meshes[m].triangle_count();
        source_bytes_ += render::mesh_gpu_bytes(ts_.scene.meshes[m]);
    }
#if defined(NBVH_HAVE_CUDA)
    if (backend_ == BackendChoice::cuda) train_device_ = cuda_device_name();
#endif
    if (train_device_.empty())
        train_device_ =
            backend_ == BackendChoice::cuda
                ? std::string("cuda")
                : strfmt("%u CPU threads",
                         o_.threads ? o_.threads : std::max(1u, std::thread::hardware_concurrency()));

    vk::ContextOptions copt;
    copt.device = vk::parse_device_choice(o_.device);
    ctx_ = std::make_unique<vk::Context>(copt);
    accel_ = build_scene_accel(ts_.scene);
    const size_t variants = variants_of(0, o_.lods).size();
    plan();
    progress_.note(
        strfmt("study of %s: %zu neural asset(s), %llu triangles (%.2f MiB with BLAS); %zu configuration(s) "
               "x %zu camera(s) x %zu variant(s); images %ux%u at %u spp, reference %u spp; training on %s",
               o_.scene.c_str(), ts_.meshes.size(), (unsigned long long)source_triangles_,
               double(source_bytes_) / 1048576.0, configs_.size(), cams_.size(), variants, o_.render.width,
               o_.render.height, o_.render.spp, o_.ref_spp, train_device_.c_str()));
    const LogLevel level = log_level();
    set_log_level(LogLevel::warn); // the progress lines say what happens; renderer/trainer info is noise here
    try {
        classical_side();
        write_results();
        const double t_configs = progress_.elapsed_seconds();
        for (size_t i = 0; i < configs_.size(); ++i) {
            // A budget (one GPU command has 10 minutes): no configuration is started that the mean time
            // of the finished ones says would end past it.
            if (o_.budget_minutes > 0.0 && i > 0) {
                const double per_config = (progress_.elapsed_seconds() - t_configs) / double(i);
                if (progress_.elapsed_seconds() + per_config > 60.0 * o_.budget_minutes) {
                    stop_reason_ =
                        strfmt("time budget of %.1f min: configurations %zu..%zu not run (%.0f s each)",
                               o_.budget_minutes, i + 1, configs_.size(), per_config);
                    progress_.note("study: stopped at the " + stop_reason_);
                    break;
                }
            }
            run_config(i, configs_[i]);
            configs_done_ = i + 1;
            write_results();
        }
        write_results();
    } catch (...) {
        set_log_level(level);
        throw;
    }
    set_log_level(level);
    if (ctx_->validation_enabled() && ctx_->validation_message_count() > 0)
        log_warn("study: %d Vulkan validation messages", ctx_->validation_message_count());
    progress_.note(strfmt("wrote %s/study.json and study.csv (%zu rows) in %s", o_.out_dir.c_str(),
                          rows_.size(), strfmt("%.0f s", progress_.elapsed_seconds()).c_str()));
}

} // namespace

void run_study(const StudyOptions& options) { StudyRun(options).run(); }

} // namespace nbvh::app
