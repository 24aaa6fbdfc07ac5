// One viewer session: the state the frame loop (viewer.cpp) works on, and every way it changes —
// panel actions, script commands, dropped files, live-training snapshots — through one set of methods,
// so a script exercises exactly what a user's clicks do. The viewer owns UI state; renderers, comparer
// and trainer own theirs (view_renderers.h, compare.h, live_training.h).
#pragma once
#include <cstdint>
#include <chrono>
#include <memory>
#include <string>

#include "app/viewer/compare.h"
#include "app/viewer/live_training.h"
#include "app/viewer/loss_view.h"
#include "app/viewer/orbit_camera.h"
#include "app/viewer/presenter.h"
#include "app/viewer/script.h"
#include "app/viewer/stats_panel.h"
#include "app/viewer/ui_panel.h"
#include "app/viewer/view_renderers.h"
#include "app/viewer/viewer_scene.h"
#include "engine/vk/context.h"

namespace nbvh::viewer {

class ViewerSession {
public:
    ViewerSession(const vk::Context& ctx, std::unique_ptr<ViewerScene> view, const SceneOptions& scene_options,
                  const ViewSettings& settings, uint32_t width, uint32_t height);

    // Start of a frame: the window size, dropped files, a finished training snapshot, script commands
    // due now, then the settings applied and the films advanced. Returns false when the script ended
    // (or said quit): draw this frame, then stop.
    bool begin_frame(uint32_t window_width, uint32_t window_height, std::vector<std::string> dropped);
    // The UI of this frame (panel, stats, split line, camera input); call between ImGui frames.
    void ui(Window& window, uint32_t window_width, uint32_t window_height);
    // What the presenter shows this frame.
    FilmSource film() const;
    // After the frame was presented: a screenshot asked for by the script is saved from `shot`.
    void end_frame(const Screenshot& shot);
    bool wants_screenshot() const { return !pending_shot_.empty(); }

    // Everything a script or the panel can do.
    void run(const ScriptCommand& command);
    void apply(const PanelActions& actions);
    void open_file(const std::string& path); // a dropped file; errors go to the status line

    bool idle() const;                       // converged, nothing running: the loop may wait for events
    const PanelInfo& info() const { return info_; }
    const ViewSettings& settings() const { return settings_; }
    const ViewRenderers& renderers() const { return renderers_; }
    void set_script(ScriptRunner script) { script_ = std::move(script); }
    // Live training's CUDA device (LiveTrainer::set_cuda_device): the view's GPU under --device gpu:N.
    void train_on_gpu(std::string uuid) { trainer_.set_cuda_device(std::move(uuid)); }
    nlohmann::json report() const;

private:
    std::unique_ptr<ViewerScene> replace_view(std::unique_ptr<ViewerScene> next, bool keep_camera);
    void switch_view(std::unique_ptr<ViewerScene> next, bool keep_camera);
    void swap_model(std::shared_ptr<const NeuralModel> model, const std::string& name,
                    std::shared_ptr<const std::vector<float>> node_loss);
    void set_model_info();
    void update_loss_view();
    void configure();
    void fail(const std::string& what); // status line + log, the viewer keeps running
    void refresh_memory();
    StatsView stats_view() const;

    const vk::Context& ctx_;
    std::unique_ptr<ViewerScene> view_;
    SceneOptions scene_options_;
    ViewSettings settings_;
    PanelInfo info_;
    OrbitCamera camera_;
    ViewRenderers renderers_;
    Comparer comparer_;
    LiveTrainer trainer_;
    ScriptRunner script_;
    NeuralMemory memory_;
    uint32_t width_ = 0, height_ = 0;
    bool rebuild_ = true, camera_moved_ = false, restart_ = false, quit_ = false;
    bool wait_training_ = false;
    std::chrono::steady_clock::time_point wait_deadline_;
    std::string pending_shot_;
    LossImage loss_;          // the loss view's image (loss_view.h)
    bool loss_stale_ = true;  // camera, LoD, model or size changed since it was made
};

} // namespace nbvh::viewer
