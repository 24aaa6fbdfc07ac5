#include "app/viewer/viewer_session.h"

#include <algorithm>
#include <cmath>

#include <imgui.h>

#include "app/output_path.h"
#include "app/viewer/imgui_layer.h"
#include "engine/core/error.h"
#include "engine/core/image.h"
#include "engine/core/log.h"

namespace nbvh::viewer {

ViewerSession::ViewerSession(const vk::Context& ctx, std::unique_ptr<ViewerScene> view,
                             const SceneOptions& scene_options, const ViewSettings& settings, uint32_t width,
                             uint32_t height)
    : ctx_(ctx), view_(std::move(view)), scene_options_(scene_options), settings_(settings),
      camera_(view_->home), renderers_(ctx), width_(width), height_(height) {
    info_.scene = view_->source;
    info_.device = ctx.features().device_name;
    replace_view(std::move(view_), true);
}

void ViewerSession::fail(const std::string& what) {
    info_.status = "error: " + what;
    log_error("view: %s (the viewer keeps running)", what.c_str());
}

void ViewerSession::refresh_memory() {
    memory_ = neural_memory(*view_, uint32_t(std::max(0, settings_.lod)));
}

// Installs `next` (the renderers of the previous view go first: they point into it) and returns the
// previous view.
std::unique_ptr<ViewerScene> ViewerSession::replace_view(std::unique_ptr<ViewerScene> next, bool keep_camera) {
    renderers_.clear();
    comparer_.invalidate();
    std::unique_ptr<ViewerScene> old = std::move(view_);
    view_ = std::move(next);
    info_.scene = view_->source;
    info_.can_train = view_->has_neural_instances();
    info_.flip_mean = -1.0;
    set_model_info();
    if (!view_->model) settings_.view = ViewMode::image;
    if (!keep_camera) camera_ = OrbitCamera(view_->home);
    refresh_memory();
    rebuild_ = true;
    return old;
}

// Installs `next` and builds its renderers now; when that fails the previous view comes back and the
// error is rethrown (the viewer keeps showing what it showed).
void ViewerSession::switch_view(std::unique_ptr<ViewerScene> next, bool keep_camera) {
    const OrbitCamera camera = camera_;
    const ViewSettings settings = settings_;
    std::unique_ptr<ViewerScene> old = replace_view(std::move(next), keep_camera);
    try {
        configure();
    } catch (const Error&) {
        if (!old) throw;
        replace_view(std::move(old), true);
        camera_ = camera;
        settings_ = settings;
        configure();
        throw;
    }
}

void ViewerSession::set_model_info() {
    info_.has_model = view_->model != nullptr;
    info_.has_node_loss = view_->node_loss != nullptr;
    info_.lod_node_counts = view_->lod_node_counts();
    if (view_->model) {
        const int lods = int(std::max(1u, view_->model->lod_count));
        settings_.lod = std::min(settings_.lod, lods - 1);
        // The renderer's choice made visible on the slider: the coarsest LoD (never finer than lod).
        if (settings_.secondary_lod == render::SECONDARY_LOD_COARSEST) settings_.secondary_lod = std::max(settings_.lod, lods - 1);
        settings_.secondary_lod = std::min(settings_.secondary_lod, lods - 1);
    }
    if (!view_->node_loss && settings_.view == ViewMode::loss) settings_.view = ViewMode::image;
    loss_stale_ = true;
}

void ViewerSession::swap_model(std::shared_ptr<const NeuralModel> model, const std::string& name,
                               std::shared_ptr<const std::vector<float>> node_loss) {
    if (!(view_->model && same_assets(*view_->model, *model))) {
        auto next = with_model(*view_, std::move(model), name); // binds the scene, builds its BVHs
        next->node_loss = std::move(node_loss);
        switch_view(std::move(next), true);
        set_model_info();
        return;
    }
    // Same assets: the bound scene and its BVHs stay, the renderer takes the model as an upload
    // (WavefrontRenderer::apply); the classical reference of a compare view keeps its film. The old
    // model stays alive until the renderer has let go of it.
    ViewerScene& v = *view_;
    std::shared_ptr<const NeuralModel> old = v.model;
    std::shared_ptr<const std::vector<float>> old_loss = v.node_loss;
    const std::string old_name = v.model_name;
    const ViewSettings old_settings = settings_;
    v.model = std::move(model);
    v.model_name = name;
    v.node_loss = std::move(node_loss);
    set_model_info();
    configure();
    if (renderers_.main() && renderers_.main_model() != v.model.get()) { // refused: the old model stays
        const std::string why = info_.status;
        v.model = std::move(old);
        v.model_name = old_name;
        v.node_loss = std::move(old_loss);
        settings_ = old_settings;
        set_model_info();
        configure();
        throw Error(why.empty() ? "the model could not be swapped in" : why);
    }
}

void ViewerSession::open_file(const std::string& path) {
    try {
        const DropKind kind = classify_drop(path);
        const float aspect = float(width_) / float(std::max(1u, height_));
        if (kind == DropKind::model) {
            auto model = std::make_shared<const NeuralModel>(load_model(path));
            if (view_->model && same_assets(*view_->model, *model)) {
                trainer_.stop();
                swap_model(std::move(model), path, nullptr); // an upload: scene and BVHs stay
            } else {
                auto next = with_model(*view_, model, path); // refused when it does not match the scene
                trainer_.stop();
                switch_view(std::move(next), true);
            }
        } else {
            std::unique_ptr<ViewerScene> next;
            std::string note;
            if (view_->model) { // keep the model when it answers the new scene too
                try {
                    next = load_viewer_scene(path, scene_options_, view_->model, view_->model_name, aspect);
                } catch (const Error& e) {
                    note = std::string(" (without the model: ") + e.what() + ")";
                }
            }
            if (!next) next = load_viewer_scene(path, scene_options_, nullptr, "", aspect);
            trainer_.stop();
            switch_view(std::move(next), false);
            info_.status = "opened " + path + note;
            return;
        }
        info_.status = "opened " + path;
    } catch (const Error& e) {
        fail(e.what());
    }
}

void ViewerSession::configure() {
    const Camera cam = camera_.camera();
    info_.status = renderers_.configure(*view_, settings_, width_, height_, cam);
    comparer_.invalidate();
    loss_stale_ = true;
    info_.flip_mean = -1.0;
    refresh_memory();
    rebuild_ = false;
}

void ViewerSession::apply(const PanelActions& act) {
    if (act.reset_camera) {
        camera_.reset();
        camera_moved_ = true;
    }
    rebuild_ |= act.rebuild;
    restart_ |= act.reset_accumulation;
    try {
        if (act.train_start) trainer_.start(view_->scene, view_->source, settings_.train);
        if (act.train_pause) trainer_.set_paused(trainer_.status().state != "paused");
        if (act.train_stop) trainer_.stop();
        if (!act.train_save.empty()) {
            const auto model = trainer_.latest_model();
            if (!model) throw Error("no trained model to save yet");
            app::check_output_path(act.train_save, "save", {view_->source});
            save_model(act.train_save, *model);
            info_.status = "saved " + act.train_save;
            log_info("view: saved the trained model to %s", act.train_save.c_str());
        }
    } catch (const Error& e) {
        fail(e.what());
    }
}

void ViewerSession::run(const ScriptCommand& c) {
    PanelActions act;
    switch (c.op) {
    case ScriptOp::frames: script_.wait_frames(c.count); break;
    case ScriptOp::set:
        try {
            act = apply_setting(settings_, c.key, c.value, info_.lod_node_counts);
        } catch (const Error& e) {
            fail(e.what());
        }
        break;
    case ScriptOp::orbit:
        camera_.orbit(c.x, c.y);
        camera_moved_ = true;
        break;
    case ScriptOp::zoom:
        camera_.zoom(c.x);
        camera_moved_ = true;
        break;
    case ScriptOp::reset_camera: act.reset_camera = true; break;
    case ScriptOp::restart: act.reset_accumulation = true; break;
    case ScriptOp::compare:
        if (rebuild_) configure();
        if (renderers_.reference()) comparer_.refresh_now(*renderers_.main(), *renderers_.reference(), settings_);
        else fail("compare: the view compares nothing (set view split, difference or flip with a model)");
        break;
    case ScriptOp::drop: open_file(c.value); break;
    case ScriptOp::screenshot:
        pending_shot_ = c.value;
        script_.wait_frames(1);
        break;
    case ScriptOp::report:
        try {
            app::write_text_atomically(c.value, report().dump(2) + "\n");
        } catch (const Error& e) {
            fail(e.what());
        }
        break;
    case ScriptOp::train:
        if (c.key == "start") act.train_start = true;
        else if (c.key == "pause" || c.key == "resume") trainer_.set_paused(c.key == "pause");
        else if (c.key == "stop") act.train_stop = true;
        else if (c.key == "save") act.train_save = c.value;
        else if (c.key == "wait") {
            wait_training_ = true;
            wait_deadline_ = std::chrono::steady_clock::now() +
                             std::chrono::milliseconds(int64_t(double(c.x) * 1000.0));
        }
        break;
    case ScriptOp::quit: quit_ = true; break;
    }
    apply(act);
}

bool ViewerSession::begin_frame(uint32_t ww, uint32_t wh, std::vector<std::string> dropped) {
    if (ww > 0 && wh > 0 && (ww != width_ || wh != height_)) {
        width_ = ww; // the film follows the window
        height_ = wh;
        rebuild_ = true;
    }
    for (const std::string& path : dropped) open_file(path);
    // Read before taking the model: the worker publishes its final model before it ends, so a run seen
    // ended here has nothing left to take after this frame's take_model.
    const bool training_ended = !trainer_.active();
    // A newer model from live training goes into the view (the final one included).
    std::shared_ptr<const std::vector<float>> node_loss;
    if (auto model = trainer_.take_model(&node_loss)) {
        try {
            swap_model(std::move(model), "live training", std::move(node_loss));
        } catch (const Error& e) {
            fail(e.what());
        }
    }
    const TrainStatus ts = trainer_.status();
    if (wait_training_ && training_ended) wait_training_ = false;
    if (wait_training_ && std::chrono::steady_clock::now() > wait_deadline_)
        throw Error("script: train wait: the training did not end in time");
    while (!wait_training_ && !quit_) {
        const ScriptCommand* c = script_.next();
        if (!c) break;
        run(*c);
    }
    const bool script_over = quit_ || (script_.active() && script_.finished() && !wait_training_);

    if (rebuild_) configure();
    if (camera_moved_ || restart_) renderers_.set_camera(camera_.camera());
    loss_stale_ |= camera_moved_;
    camera_moved_ = restart_ = false;
    renderers_.render(uint32_t(settings_.spp_per_frame), uint32_t(std::max(0, settings_.max_samples)), info_);
    info_.model_swaps = renderers_.model_swaps();
    update_loss_view();
    if (const render::WavefrontRenderer* ref = renderers_.reference()) {
        comparer_.update(*renderers_.main(), *ref, settings_);
        if (comparer_.has_result()) {
            const CompareResult& r = comparer_.result();
            info_.flip_mean = r.flip_mean;
            info_.flip_samples = r.test_samples;
            info_.flip_reference_samples = r.reference_samples;
        }
    }
    info_.width = width_;
    info_.height = height_;
    info_.train_state = ts.state;
    info_.train_step = ts.step;
    info_.train_steps = ts.steps;
    info_.train_nodes = ts.nodes;
    info_.train_loss = ts.loss;
    info_.train_eta_s = ts.eta_s;
    info_.train_snapshots = ts.snapshots;
    info_.train_loss_history = ts.loss_history;
    return !script_over;
}

// The loss view's image, made again when what it shows changed (loss_view.h: one traced ray a pixel).
void ViewerSession::update_loss_view() {
    render::WavefrontRenderer* main = renderers_.main();
    if (settings_.view != ViewMode::loss || !loss_stale_ || !main || !main->hybrid() || !view_->node_loss) return;
    loss_ = make_loss_image(*main, *view_, *view_->node_loss, camera_.camera(), uint32_t(std::max(0, settings_.lod)),
                            main->width(), main->height());
    info_.loss_lo = loss_.lo;
    info_.loss_hi = loss_.hi;
    info_.loss_leaves = loss_.leaves;
    loss_stale_ = false;
}

StatsView ViewerSession::stats_view() const {
    StatsView v;
    v.info = &info_;
    v.settings = &settings_;
    v.main = renderers_.main() ? &renderers_.main_stats() : nullptr;
    v.reference = renderers_.reference() ? &renderers_.reference_stats() : nullptr;
    v.memory = memory_;
    v.reference_builds = renderers_.reference_builds();
    return v;
}

nlohmann::json ViewerSession::report() const { return stats_json(stats_view()); }

void ViewerSession::ui(Window& window, uint32_t ww, uint32_t wh) {
    const FilmRect rect = film_rect(ww, wh, width_, height_);
    PanelActions act;
    if (settings_.show_ui) {
        act = draw_panel(settings_, info_);
        draw_stats_panel(stats_view());
        draw_split_line(settings_, rect);
    }
    camera_moved_ |= handle_input(camera_, settings_, window, rect);
    apply(act);
}

FilmSource ViewerSession::film() const {
    const render::WavefrontRenderer* main = renderers_.main();
    FilmSource f; // the renderer's size: a failed rebuild keeps the previous renderer
    f.linear = &main->output();
    f.width = main->width();
    f.height = main->height();
    f.exposure = settings_.exposure;
    f.tone_map = ToneMap::aces; // as nbvh render's PNGs
    if (settings_.view == ViewMode::loss) {
        if (!loss_stale_ && loss_.width == f.width && loss_.height == f.height) f.rgba8 = &loss_.rgba8;
        return f;
    }
    const render::WavefrontRenderer* ref = renderers_.reference();
    if (!ref || ref->width() != f.width || ref->height() != f.height) return f;
    if (settings_.view == ViewMode::split) {
        f.linear_right = &ref->output();
        f.split_column = uint32_t(std::lround(std::clamp(settings_.split, 0.0f, 1.0f) * float(f.width)));
    } else if (comparer_.has_result()) {
        const CompareResult& r = comparer_.result();
        if (r.mode == settings_.view && r.width == f.width && r.height == f.height) f.rgba8 = &r.rgba8;
    }
    return f;
}

void ViewerSession::end_frame(const Screenshot& shot) {
    script_.frame_done();
    if (pending_shot_.empty()) return;
    const std::string path = pending_shot_;
    pending_shot_.clear();
    try {
        if (!is_png_path(path)) throw Error(strfmt("screenshot '%s': expected a .png file name", path.c_str()));
        if (shot.width == 0) throw Error("screenshot: the window cannot be read back on this device");
        save_png_8bit(path, int(shot.width), int(shot.height), 3, shot.rgb.data());
        log_info("view: saved the window (%ux%u) to %s", shot.width, shot.height, path.c_str());
    } catch (const Error& e) {
        fail(e.what());
    }
}

bool ViewerSession::idle() const {
    return renderers_.converged(uint32_t(std::max(0, settings_.max_samples))) && !trainer_.active() &&
           !comparer_.busy() && !script_.active();
}

} // namespace nbvh::viewer
