// The classical side of a study and its measuring steps: each camera's converged reference (its own seed),
// the classical image of the compared seed (the noise floor) and the classical frame time, the equal-time
// classical baselines (one film per camera extended eighth by eighth), and how a row is rendered, timed
// and saved.
#include "app/study/study_run.h"

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
#include "app/study/study_references.h"
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

namespace fs = std::filesystem;

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
    if (timing_renderer) { // built with timing_options()
        opt.width = time_width_, opt.height = time_height_;
        opt.wave_memory_share = o_.render.wave_memory_share;
    }
    NBVH_CHECK(r.apply(opt));
    return median_render_stats(r, o_.repeat).gpu_ms;
}

void StudyRun::classical_side() {
    const Scene& scene = ts_.scene;
    for (CameraSide& cam : cams_) {
        const size_t c = cam.index;
        RenderOptions ref = image_options(o_.ref_spp, o_.render.seed + STUDY_REFERENCE_SEED_OFFSET);
        ref.neural.classical = true;
        render::validate(ref.neural, scene);
        // The image-size classical renderer: the reference and the floor, then the equal-time renders
        // (also of a camera whose side --references held: those not kept there are rendered anew).
        cam.classical = std::make_unique<WavefrontRenderer>(*ctx_, scene, accel_, env_, cam.camera, ref);
        if (cam.cached) {
            if (o_.save_images && c == 0) // the pixels are the PNG's: written as they are
                save_png((fs::path(o_.out_dir) / "reference_cam0.png").string(), cam.kept.reference_px);
            progress_.note(
                strfmt("camera %zu: classical side from --references %s: noise floor %.4f, classical "
                       "%.3f ms/frame, %zu equal-time FLIPs",
                       c, o_.references_dir.c_str(), cam.kept.noise_floor, cam.kept.classical_ms,
                       cam.kept.equal_time_flip.size()));
        } else {
            progress_.begin(StudyTask::render,
                            pixel_samples(o_.ref_spp) + pixel_samples(o_.render.spp) + timing_work(),
                            strfmt("camera %zu: classical reference (%u spp), noise floor (%u spp)", c,
                                   o_.ref_spp, o_.render.spp));
            render::RenderResult r = cam.classical->render();
            cam.kept.exposure = fixed_exposure_ ? *fixed_exposure_ : auto_exposure(r.image).stops;
            const Image ref_px = as_png_pixels(r.image, cam.kept.exposure);
            if (o_.save_images && c == 0) save("reference_cam0.png", r.image, cam.kept.exposure);
            RenderOptions same = image_options(o_.render.spp, o_.render.seed);
            same.neural.classical = true;
            const Image floor_px = as_png_pixels(render_with(*cam.classical, same).image, cam.kept.exposure);
            cam.film_spp = o_.render.spp;
            cam.ref_flip.emplace(ref_px);
            cam.floor_flip.emplace(floor_px);
            cam.kept.noise_floor = cam.ref_flip->compare(floor_px).mean;
            std::unique_ptr<WavefrontRenderer> timing;
            if (separate_timing()) {
                RenderOptions t = timing_options();
                t.neural.classical = true;
                timing = std::make_unique<WavefrontRenderer>(*ctx_, scene, accel_, env_, cam.camera, t);
            }
            cam.kept.classical_ms = time_frame(*cam.classical, timing.get(), same);
            cam.kept.equal_time_flip[o_.render.spp] = cam.kept.noise_floor;
            if (!o_.references_dir.empty()) { // kept at once: a later failure loses no render
                cam.kept.reference_px = ref_px, cam.kept.floor_px = floor_px;
                save_reference(o_.references_dir, c, reference_key(cam), cam.kept);
                cam.kept_equal_time = cam.kept.equal_time_flip.size();
            }
            progress_.end(strfmt("noise floor %.4f, classical %.3f ms/frame (%u spp), exposure %+.2f stops",
                                 cam.kept.noise_floor, cam.kept.classical_ms, o_.time_spp,
                                 cam.kept.exposure));
        }
        if (o_.equal_time_upto > 0.0 && !cam.cached) { // equal-time FLIPs up front (kept with the references)
            uint32_t spp = 0;
            equal_time(cam, o_.equal_time_upto, &spp);
        }

        StudyRow row;
        row.variant = "classical";
        row.camera = int(c);
        row.memory_bytes = source_bytes_;
        row.triangles = source_triangles_;
        row.compression = 1.0;
        row.frame_ms = row.classical_frame_ms = cam.kept.classical_ms;
        row.ratio_to_classical = 1.0;
        row.flip = row.noise_floor = cam.kept.noise_floor;
        row.flip_same_seed = 0.0;
        mark_floor(row);
        row.equal_time_spp = o_.render.spp;
        row.equal_time_flip = cam.kept.noise_floor;
        rows_.push_back(row);
    }
    keep_references();
}

// The camera's film holds the floor render's samples (the compared seed, `spp`) again, so the equal-time
// renders extend it: every equal-time FLIP comes from the same sums, whether the film was left by the floor
// render or by the timed frames, or the camera's side came from --references.
void StudyRun::start_film(CameraSide& cam) {
    RenderOptions same = image_options(o_.render.spp, o_.render.seed);
    same.neural.classical = true;
    render_with(*cam.classical, same);
    cam.film_spp = o_.render.spp;
}

nlohmann::json StudyRun::reference_key(const CameraSide& cam) const {
    const RenderOptions t = timing_options();
    const vk::DeviceFeatures& f = ctx_->features();
    return {{"commit", o_.commit},
            {"device", f.device_name},
            {"driver", f.driver_name + " " + f.driver_info},
            {"scene", o_.scene},
            {"scene_hash", strfmt("%016llx", (unsigned long long)ts_.source_hash)},
            {"neural", o_.neural_glob},
            {"camera", camera_string(cam.camera)},
            {"env", o_.env},
            {"env_hash", env_hash_},
            {"env_rotation", o_.env_rotation ? *o_.env_rotation : 0.0f},
            {"width", o_.render.width},
            {"height", o_.render.height},
            {"spp", o_.render.spp},
            {"ref_spp", o_.ref_spp},
            {"seed", o_.render.seed},
            {"max_depth", o_.render.max_depth},
            {"rr_start_depth", o_.render.rr_start_depth},
            {"sampler", render::sampler_name(o_.render.sampler)},
            {"texture_path", int(o_.render.texture_path)},
            {"sort_rays", o_.render.sort_rays},
            {"max_wave_pixels", o_.render.max_wave_pixels},
            {"exposure", o_.exposure},
            {"time_spp", o_.time_spp},
            {"time_width", t.width},
            {"time_height", t.height},
            {"repeat", o_.repeat}};
}

void StudyRun::load_references() {
    if (o_.references_dir.empty()) return;
    for (CameraSide& cam : cams_) {
        std::optional<CachedCamera> k = load_reference(o_.references_dir, cam.index, reference_key(cam));
        if (!k) continue;
        if (k->reference_px.width != int(o_.render.width) || k->reference_px.height != int(o_.render.height))
            throw Error(strfmt("--references %s: camera %zu's images are not %ux%u",
                               o_.references_dir.c_str(), cam.index, o_.render.width, o_.render.height));
        cam.cached = true;
        cam.kept = std::move(*k);
        cam.ref_flip.emplace(cam.kept.reference_px);
        cam.floor_flip.emplace(cam.kept.floor_px);
        cam.film_spp = 0; // the film holds nothing of the compared seed: an equal-time miss renders anew
        cam.kept_equal_time = cam.kept.equal_time_flip.size();
    }
}

void StudyRun::keep_references() {
    if (o_.references_dir.empty()) return;
    for (CameraSide& cam : cams_) {
        if (!cam.ref_flip || cam.kept.equal_time_flip.size() == cam.kept_equal_time) continue; // nothing new
        save_reference(o_.references_dir, cam.index, reference_key(cam), cam.kept);
        cam.kept_equal_time = cam.kept.equal_time_flip.size();
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
    if (auto it = cam.kept.equal_time_flip.find(spp); it != cam.kept.equal_time_flip.end()) return it->second;
    auto flip_of = [&](const Image& linear) {
        return cam.ref_flip->compare(as_png_pixels(linear, cam.kept.exposure)).mean;
    };
    if (spp > base && (cam.film_spp == 0 || cam.classical->accumulated_samples() != cam.film_spp))
        start_film(cam); // the floor's samples again, extended below as in the run that made the reference
    const bool extend = cam.film_spp > 0 && cam.film_spp < spp && cam.classical->accumulated_samples() == cam.film_spp;
    if (!extend) {
        RenderOptions opt = image_options(spp, o_.render.seed);
        opt.neural.classical = true;
        cam.kept.equal_time_flip[spp] = flip_of(render_with(*cam.classical, opt).image);
        cam.film_spp = spp;
        return cam.kept.equal_time_flip[spp];
    }
    for (uint32_t e = 1; cam.film_spp < spp; ++e) {
        const uint32_t next = spp_of(e);
        if (next <= cam.film_spp) continue;
        const Image mean = cam.classical->render_progressive(next - cam.film_spp).image;
        cam.film_spp = next;
        if (!cam.kept.equal_time_flip.count(next)) cam.kept.equal_time_flip[next] = flip_of(mean);
    }
    return cam.kept.equal_time_flip.at(spp);
}

} // namespace nbvh::app::study
