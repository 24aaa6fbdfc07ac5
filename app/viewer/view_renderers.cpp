#include "app/viewer/view_renderers.h"

#include <algorithm>
#include <chrono>

#include "engine/core/error.h"
#include "engine/core/log.h"

namespace nbvh::viewer {

namespace {

render::RenderOptions base_options(const ViewSettings& s, uint32_t width, uint32_t height) {
    render::RenderOptions o;
    o.width = width;
    o.height = height;
    o.spp = 1;
    o.max_depth = uint32_t(std::max(1, s.max_depth));
    return o;
}

void set_overrides(const ViewSettings& s, render::RenderOptions& o) {
    o.neural.roughness = s.override_material ? s.roughness : -1.0f;
    o.neural.metallic = s.override_material ? s.metallic : -1.0f;
}

bool same_main(const render::RenderOptions& a, const render::RenderOptions& b) {
    const render::NeuralRenderOptions &n = a.neural, &m = b.neural;
    return a.width == b.width && a.height == b.height && a.max_depth == b.max_depth && n.model == m.model &&
           n.classical == m.classical && n.lod == m.lod && n.secondary_lod == m.secondary_lod &&
           n.max_rounds == m.max_rounds && n.roughness == m.roughness && n.metallic == m.metallic;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

} // namespace

bool is_compare_view(const ViewerScene& view, const ViewSettings& s) {
    return view.model != nullptr && needs_reference(s.view);
}

render::RenderOptions main_options(const ViewerScene& view, const ViewSettings& s, uint32_t width, uint32_t height) {
    render::RenderOptions o = base_options(s, width, height);
    if (!view.model) return o;
    const int lods = int(std::max(1u, view.model->lod_count));
    o.neural.model = view.model.get(); // also when classical: apply() switches only within one model
    // The compare and loss views show the hybrid render whatever `neural` says.
    o.neural.classical = !s.neural && s.view == ViewMode::image;
    o.neural.lod = uint32_t(std::clamp(s.lod, 0, lods - 1));
    o.neural.secondary_lod = std::min(s.secondary_lod, lods - 1);
    o.neural.max_rounds = uint32_t(std::clamp(s.max_leaves, 1, 256));
    o.neural.max_rounds_secondary =
        0; // the slider is every ray's budget (nbvh render: 4 after the first hit)
    set_overrides(s, o);
    return o;
}

render::RenderOptions reference_options(const ViewerScene& view, const ViewSettings& s, uint32_t width,
                                        uint32_t height) {
    render::RenderOptions o = base_options(s, width, height);
    o.neural.classical = true; // the true scene: neural instances from their triangles
    if (view.model) set_overrides(s, o);
    return o;
}

std::string ViewRenderers::configure(const ViewerScene& view, const ViewSettings& s, uint32_t width,
                                     uint32_t height, const Camera& camera) {
    if (&view != view_) {
        clear();
        view_ = &view;
    }
    std::string refused;
    const render::RenderOptions o = main_options(view, s, width, height);
    try {
        if (main_ && same_main(o, main_options_)) {
            // Nothing the main renderer uses changed (e.g. split -> FLIP view): its film keeps going.
        } else if (main_ && main_->apply(o)) {
            live_updates_++;
            if (o.neural.model != main_options_.neural.model) model_swaps_++;
        } else {
            // With a model the renderer is built hybrid, so that neural on/off is an upload afterwards
            // (a classical-built renderer has no neural passes to switch to).
            render::RenderOptions first = o;
            const bool overrides = o.neural.roughness >= 0.0f || o.neural.metallic >= 0.0f;
            if (o.neural.model && o.neural.classical && !overrides) first.neural.classical = false;
            auto next = std::make_unique<render::WavefrontRenderer>(ctx_, view.scene, view.accel, view.env, camera,
                                                                    first);
            if (first.neural.classical != o.neural.classical) NBVH_CHECK(next->apply(o));
            ctx_.wait_idle(); // frames in flight may still read the old renderer's output (film_stage.h)
            main_ = std::move(next);
            builds_++;
        }
        main_options_ = o;
    } catch (const Error& e) {
        if (!main_) throw; // nothing to keep showing
        refused = strfmt("not applied: %s", e.what());
    }
    compare_ = is_compare_view(view, s);
    if (!compare_) return refused;
    const render::RenderOptions r = reference_options(view, s, width, height);
    auto same = [](const render::RenderOptions& a, const render::RenderOptions& b) {
        return a.width == b.width && a.height == b.height && a.max_depth == b.max_depth &&
               a.neural.roughness == b.neural.roughness && a.neural.metallic == b.neural.metallic;
    };
    if (reference_ && same(r, reference_options_)) return refused; // its film keeps accumulating
    try {
        if (!(reference_ && reference_->apply(r))) {
            auto next = std::make_unique<render::WavefrontRenderer>(ctx_, view.scene, view.accel, view.env,
                                                                    camera, r);
            ctx_.wait_idle();
            reference_ = std::move(next);
            reference_builds_++;
        }
        reference_options_ = r;
    } catch (const Error& e) {
        compare_ = reference_ != nullptr;
        refused = strfmt("reference not applied: %s", e.what());
    }
    return refused;
}

void ViewRenderers::set_camera(const Camera& camera) {
    if (main_) main_->set_camera(camera);
    if (reference_) reference_->set_camera(camera); // also when hidden: it restarts on the view shown next
}

bool ViewRenderers::converged(uint32_t max_samples) const {
    auto done = [&](const render::WavefrontRenderer* r) {
        return !r || (max_samples > 0 && r->accumulated_samples() >= max_samples);
    };
    return main_ && done(main_.get()) && done(reference());
}

void ViewRenderers::render(uint32_t spp, uint32_t max_samples, PanelInfo& info) {
    auto due = [&](const render::WavefrontRenderer* r) {
        return r && (max_samples == 0 || r->accumulated_samples() < max_samples);
    };
    if (due(main_.get())) {
        const auto t0 = std::chrono::steady_clock::now();
        // The mean stays on the GPU: the presenter's display pass tone-maps it there.
        main_stats_ = main_->render_progressive(spp, false).stats;
        info.frame_ms = ms_since(t0);
        info.rays_per_second = main_stats_.rays_per_second();
        info.neural_path = main_stats_.neural_path;
        info.neural_queries_per_ray = main_stats_.neural_queries_per_ray();
    }
    if (due(reference())) {
        const auto t0 = std::chrono::steady_clock::now();
        reference_stats_ = reference_->render_progressive(spp, false).stats;
        info.reference_frame_ms = ms_since(t0);
    }
    info.samples = main_ ? main_->accumulated_samples() : 0;
    info.reference_samples = reference() ? reference()->accumulated_samples() : 0;
    info.renderer_builds = builds_;
    info.live_updates = live_updates_;
}

void ViewRenderers::clear() {
    if (main_ || reference_) ctx_.wait_idle();
    main_.reset();
    reference_.reset();
    view_ = nullptr;
    compare_ = false;
}

} // namespace nbvh::viewer
