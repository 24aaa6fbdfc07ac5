// The viewer's path tracers: the main one (what `image` view shows: hybrid, or classical with neural
// off) and, for the compare views, a classical reference accumulating the same camera beside it. Both
// are WavefrontRenderers over the same ViewerScene; each uploads its own copy of the scene buffers
// (the engine has no shared scene upload yet), so a compare view costs a second scene's GPU memory.
// Settings go through WavefrontRenderer::apply (uploads); a renderer is built only for what apply
// refuses (film size, another model, material overrides baked into a classical reference), and the
// counters say which happened.
#pragma once
#include <cstdint>
#include <memory>
#include <string>

#include "app/viewer/ui_panel.h"
#include "app/viewer/viewer_scene.h"
#include "engine/render/wavefront.h"
#include "engine/vk/context.h"

namespace nbvh::viewer {

class ViewRenderers {
public:
    explicit ViewRenderers(const vk::Context& ctx) : ctx_(ctx) {}

    // Applies `settings` for a film of width x height over `view` (a different ViewerScene than the last
    // call drops both renderers first). Throws nbvh::Error when a setting is refused and there is no
    // renderer to keep showing; otherwise a refused setting leaves the previous state and returns its
    // message ("" when all applied).
    std::string configure(const ViewerScene& view, const ViewSettings& settings, uint32_t width, uint32_t height,
                          const Camera& camera);
    // Restarts both films with the view of `camera`.
    void set_camera(const Camera& camera);
    // Adds `spp` samples to each film below `max_samples` (0: no limit); the reference only in the
    // compare views. Fills the panel's frame numbers.
    void render(uint32_t spp, uint32_t max_samples, PanelInfo& info);
    // Drops both renderers (before their ViewerScene goes).
    void clear();

    render::WavefrontRenderer* main() const { return main_.get(); }
    // The classical reference, when the view compares (else null).
    render::WavefrontRenderer* reference() const { return compare_ ? reference_.get() : nullptr; }
    bool converged(uint32_t max_samples) const;
    const render::RenderStats& main_stats() const { return main_stats_; }
    const render::RenderStats& reference_stats() const { return reference_stats_; }
    uint32_t builds() const { return builds_; }
    uint32_t reference_builds() const { return reference_builds_; }
    uint32_t live_updates() const { return live_updates_; }
    uint32_t model_swaps() const { return model_swaps_; } // live updates that replaced the model
    // The model the main renderer renders with (as last applied; null: none).
    const NeuralModel* main_model() const { return main_ ? main_options_.neural.model : nullptr; }

private:
    const vk::Context& ctx_;
    const ViewerScene* view_ = nullptr;
    std::unique_ptr<render::WavefrontRenderer> main_, reference_;
    render::RenderOptions main_options_, reference_options_; // as last applied
    bool compare_ = false;
    render::RenderStats main_stats_, reference_stats_;
    uint32_t builds_ = 0, reference_builds_ = 0, live_updates_ = 0, model_swaps_ = 0;
};

// The main renderer's options for `settings` (hybrid when the view has a model and neural is on or a
// compare view is shown) and the classical reference's.
render::RenderOptions main_options(const ViewerScene& view, const ViewSettings& settings, uint32_t width,
                                   uint32_t height);
render::RenderOptions reference_options(const ViewerScene& view, const ViewSettings& settings, uint32_t width,
                                        uint32_t height);
bool is_compare_view(const ViewerScene& view, const ViewSettings& settings);

} // namespace nbvh::viewer
