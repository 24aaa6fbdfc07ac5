// The order of work: the classical side of every camera first (converged reference, the noise floor at
// the compared spp, the classical frame time), then per configuration: train, decimate to its bytes,
// and per camera every variant of the model (frame time, image, FLIP), the decimated meshes, and the
// classical renders at equal time (cached per spp). The hybrid renderers are built once for the sweep and
// switched between models and rows with WavefrontRenderer::apply (uploads, no new pipelines).
#include "app/study/study_runner.h"
#include "app/study/study_run.h"

#include <algorithm>
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
#include "engine/neural/model_file.h"
#include "engine/render/decimation.h"
#include "engine/render/gpu_memory.h"
#include "engine/render/neural_stage.h"
#include "engine/render/wavefront.h"
#include "engine/vk/context.h"
#include "trainer/compact_hash.h"
#include "trainer/model_export.h"
#include "trainer/trainer.h"
#if defined(NBVH_HAVE_CUDA)
#include "trainer/cuda/cuda_backend.h"
#endif

namespace nbvh::app {
namespace study {
namespace {

namespace fs = std::filesystem;

std::string utc_now() {
    const std::time_t t = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&t, &tm);
    char buf[32];
    std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buf;
}
} // namespace

void StudyRun::plan() {
    const double cams = double(cams_.size());
    for (const CameraSide& cam : cams_)
        if (!cam.cached)
            progress_.plan(StudyTask::render,
                           pixel_samples(o_.ref_spp) + pixel_samples(o_.render.spp) + timing_work());
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

void StudyRun::write_results() const {
    std::vector<StudyRow> all = rows_;
    const std::vector<StudyRow> means = mean_over_cameras(rows_);
    all.insert(all.end(), means.begin(), means.end());
    write_text_atomically((fs::path(o_.out_dir) / "study.csv").string(), study_csv(all, o_.scene));
    nlohmann::json cams = nlohmann::json::array();
    for (size_t c = 0; c < cams_.size(); ++c)
        cams.push_back({{"camera", cams_[c].index},
                        {"from_references", cams_[c].cached},
                        {"view", camera_string(cams_[c].camera)},
                        {"exposure_stops", cams_[c].kept.exposure},
                        {"noise_floor", cams_[c].kept.noise_floor},
                        {"classical_frame_ms", cams_[c].kept.classical_ms}});
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
          {"reference_seed", o_.render.seed + STUDY_REFERENCE_SEED_OFFSET},
          {"max_depth", o_.render.max_depth},
          {"time_spp", o_.time_spp},
          {"time_width", t.width},
          {"time_height", t.height},
          {"repeat", o_.repeat},
          {"max_leaves", o_.render.neural.max_rounds},
          {"max_leaves_secondary", o_.render.neural.max_rounds_secondary}, // 0: max_leaves; the cap row: 0
          {"max_leaves_shadow", o_.render.neural.max_rounds_shadow}, // 0: max_leaves_secondary; the cap row: 0
          {"cap_study", o_.cap_study},
          {"leaves_per_round", o_.render.neural.leaves_per_round},
          {"leaves_per_round_camera", o_.render.neural.leaves_per_round_camera},
          {"neural_path", render::neural_path_name(neural_path_)},
          {"sampler", render::sampler_name(o_.render.sampler)},
          {"image_wave_memory_share", image_memory_share_},
          {"neural_kernel", kernel_},
          {"lods", o_.lods},
          {"exposure", o_.exposure},
          {"references", o_.references_dir},
          {"equal_time_upto", o_.equal_time_upto},
          {"neural_scratch_bytes_per_ray",
           render::neural_scratch_bytes_per_ray(render::effective_leaves_per_round(o_.render.neural))}}},
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
    if (o_.references_only && o_.references_dir.empty())
        throw Error("--references-only needs --references DIR (the folder it writes)");
    if (!o_.reference_cameras.empty() && !o_.references_only)
        throw Error("--reference-cameras goes with --references-only (a sweep compares every camera)");
    for (uint32_t c : o_.reference_cameras)
        if (c >= o_.camera_count)
            throw Error(strfmt("--reference-cameras %u: the study has cameras 0 to %u (--cameras)", c,
                               o_.camera_count - 1));
    time_width_ = o_.time_width;
    time_height_ = o_.time_height;
    neural_path_ = render::parse_neural_path(o_.neural_path);
    (void)vk::parse_device_spec(o_.device); // a bad --device fails before the scene loads
    fixed_exposure_ = parse_exposure(o_.exposure);
    backend_ = resolve_backend(parse_backend(o_.backend));
    ts_ = load_training_scene(o_.scene, o_.neural_glob, o_.asset_glob);
    env_ = choose_environment(ts_.scene, o_.env);
    if (o_.env_rotation) env_.rotation = *o_.env_rotation * 3.14159265358979f / 180.0f;
    if (!o_.references_dir.empty() && !o_.env.empty() && o_.env != "none")
        env_hash_ = strfmt("%016llx", (unsigned long long)fnv1a64_file(o_.env));
    cams_.resize(0);
    const std::vector<Camera> cameras = study_cameras(ts_.scene, o_.cameras, o_.camera_count,
                                                      float(o_.render.width) / float(o_.render.height));
    const auto& only = o_.reference_cameras;
    for (size_t i = 0; i < cameras.size(); ++i)
        if (only.empty() || std::find(only.begin(), only.end(), uint32_t(i)) != only.end())
            cams_.push_back(CameraSide{cameras[i], i});
    fs::create_directories(o_.out_dir);

    asset_ = std::make_unique<TrainingAsset>(make_training_asset(ts_.scene, ts_.meshes));
    const TrainOptions defaults = default_train_options(backend_);
    const uint32_t default_hash =
        compact_hash_log2(*asset_, defaults.network, defaults.network.log2_hash_size);
    for (uint32_t n : o_.nodes.empty() ? std::vector<uint32_t>{defaults.target_nodes} : o_.nodes)
        for (uint32_t h : o_.hash_log2.empty() ? std::vector<uint32_t>{default_hash} : o_.hash_log2)
            configs_.push_back({n, h});
    for (const Config& c : configs_) train_options(c); // every configuration valid before the first training
    for (uint32_t m : ts_.meshes) {
        source_triangles_ += ts_.scene.meshes[m].triangle_count();
        source_bytes_ += render::mesh_gpu_bytes(ts_.scene.meshes[m]);
    }
    vk::ContextOptions copt;
    copt.set_device(o_.device);
    ctx_ = std::make_unique<vk::Context>(copt);
    device_ = ctx_->features().device_name;
    driver_ = ctx_->features().driver_name + " " + ctx_->features().driver_info;
    // --device gpu:N: train on the GPU that renders (matched by UUID), not on CUDA's first device.
    if (backend_ == BackendChoice::cuda && copt.gpu_index >= 0) use_cuda_device(ctx_->features().device_uuid);
#if defined(NBVH_HAVE_CUDA)
    if (backend_ == BackendChoice::cuda) train_device_ = cuda_device_name();
#endif
    if (train_device_.empty())
        train_device_ =
            backend_ == BackendChoice::cuda
                ? std::string("cuda")
                : strfmt("%u CPU threads",
                         o_.threads ? o_.threads : std::max(1u, std::thread::hardware_concurrency()));

    // The image renderers live together (each camera's classical one, the hybrid and the decimated
    // mesh's): their waves split half of the GPU's memory (a lone renderer may take a quarter,
    // engine/render/wave_plan.h), so a smaller card holds them all at 32 samples per wave (960x540:
    // ~3 GB classical, ~9 GB hybrid each). Timed frames keep a lone renderer's share.
    image_memory_share_ = std::min(o_.render.wave_memory_share, 0.5f / float(cams_.size() + 2));
    accel_ = build_scene_accel(ts_.scene);
    if (o_.references_only) configs_.clear(); // the classical side alone
    load_references();
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
        keep_references(); // with the equal-time FLIPs the rows added
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

} // namespace study

void run_study(const StudyOptions& options) { study::StudyRun(options).run(); }

} // namespace nbvh::app
