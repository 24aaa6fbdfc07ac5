// One `nbvh study` run: its state and steps, shared by study_runner.cpp (the order of work and the
// result files), study_classical.cpp (each camera's reference, noise floor, classical frame time and
// equal-time baselines) and study_config.cpp (one configuration: train, decimate, render every variant
// from every camera). Internal to app/study/; run_study (study_runner.h) is the entry point.
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/study/study_options.h"
#include "app/study/study_progress.h"
#include "app/study/study_references.h"
#include "app/study/study_rows.h"
#include "app/training_scene.h"
#include "engine/bvh/scene_accel.h"
#include "engine/core/flip.h"
#include "engine/neural/model_file.h"
#include "engine/render/wavefront.h"
#include "engine/vk/context.h"
#include "trainer/trainer.h"

namespace nbvh::app::study {

using render::RenderOptions;
using render::WavefrontRenderer;

struct Config {
    uint32_t nodes = 0, hash_log2 = 0;
};

// Everything of one camera that every configuration compares against.
struct CameraSide {
    Camera camera;
    size_t index = 0;    // the camera's number in the study (file names of --references, result rows)
    bool cached = false; // its classical side came from --references
    // Its classical side: the exposure of every PNG of this camera (the reference's auto exposure), the
    // noise floor, the classical frame time, the equal-time FLIPs (classical spp -> FLIP vs the reference)
    // and, with --references, the reference and floor images as PNG pixels: what the folder keeps.
    CachedCamera kept;
    // The reference (ref_spp) and the classical image (spp, compared seed) as PNG pixels, prepared once
    // for the FLIPs of every row (FlipReference: the same figures as flip_ldr, half the filtering).
    std::optional<FlipReference> ref_flip, floor_flip;
    std::unique_ptr<WavefrontRenderer> classical; // image size: reference, floor, equal-time renders
    // Samples of the compared seed in `classical`'s film (the floor render, then equal-time extensions);
    // 0 when the film holds something else.
    uint32_t film_spp = 0;
    size_t kept_equal_time = 0; // equal-time FLIPs in --references as last written or read
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
        r.wave_memory_share = image_memory_share_;
        return r;
    }
    RenderOptions timing_options() const {
        RenderOptions r = image_options(o_.time_spp, o_.render.seed);
        r.wave_memory_share = o_.render.wave_memory_share; // a timed frame's waves are a lone renderer's
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
        // The cap row raises every ray's budget (study_config.cpp), so it differs from the others also
        // where cap_study is the camera rays' budget but later rays have less.
        const uint32_t secondary = o_.render.neural.max_rounds_secondary, shadow = o_.render.neural.max_rounds_shadow;
        const bool cap_differs =
            o_.cap_study != cap || (secondary != 0 && secondary < cap) || (shadow != 0 && shadow < cap);
        if (o_.cap_study && cap_differs && config == configs_.size() / 2)
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
    nlohmann::json reference_key(const CameraSide& cam) const; // what makes a camera's classical side
    void load_references(); // the cameras --references holds (before plan(): theirs is no work)
    void keep_references(); // every camera's classical side into --references (equal-time FLIPs grown)
    void run_config(size_t index, const Config& c);
    TrainOptions train_options(const Config& c) const; // validated (throws nbvh::Error)
    double equal_time(CameraSide& cam, double ratio, uint32_t* spp_out);
    void start_film(CameraSide& cam);
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
    std::string env_hash_; // of the --env file's bytes (empty without one): in each camera's --references key
    std::vector<StudyRow> rows_;
    nlohmann::json config_json_ = nlohmann::json::array();
    std::string started_, stop_reason_;
    size_t configs_done_ = 0;
    // One hybrid renderer (and one for the timed frames) for the whole sweep, declared last so they go
    // before the context, scene and BVHs they use: each configuration's model is swapped in through
    // apply(), its scene bound once; the previous model lives until the renderers have left it.
    std::optional<Scene> hybrid_scene_;
    std::unique_ptr<NeuralModel> model_, previous_model_;
    std::unique_ptr<WavefrontRenderer> hybrid_, hybrid_timing_;
    // The image renderers live together (each camera's classical one, the hybrid, the decimated scene's):
    // their waves split half of the GPU's memory (run()).
    float image_memory_share_ = 0.25f;
};

} // namespace nbvh::app::study
