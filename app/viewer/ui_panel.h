// The viewer's Dear ImGui panel: what the user can change (ViewSettings, owned by the viewer) and
// what it shows (PanelInfo). Renderer settings (max depth, LoDs, neural on/off, neural material
// constants, the compare view) are applied when a slider is released (WavefrontRenderer::apply: an
// upload, no rebuild). A script (script.h) changes the same settings through the same PanelActions.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace nbvh::viewer {

// What the window shows. image: the main renderer (hybrid, or classical with `neural` off); the
// compare views need a model and add a classical reference renderer for the same camera:
// split (hybrid left of the split line, classical right), difference (|hybrid - classical| of the
// display bytes, times `gain`) and flip (LDR-FLIP heat map, hybrid vs classical). loss needs a model from
// live training and no reference: every N-BVH leaf seen by a primary ray in its training loss, false
// colour (paper Fig. 4; loss_view.h).
enum class ViewMode { image, split, difference, flip, loss };
const char* view_mode_name(ViewMode mode);
bool parse_view_mode(const std::string& name, ViewMode* mode); // false for an unknown name
// Whether the view shows a classical reference beside the main renderer (split, difference, flip).
bool needs_reference(ViewMode mode);

// Live training options (live_training.h): the CPU defaults of `nbvh train` scaled down for a view.
struct TrainSettings {
    int steps = 300;
    int nodes = 255;             // target N-BVH nodes
    int batch = 1024;            // rays per step
    int hash_log2 = 14;
    int lods = 3;                // as nbvh train: the view's secondary rays take the coarsest
    int threads = 1;             // CPU backend (the renderer shares the cores on lavapipe)
    int snapshot_every = 25;     // steps between models swapped into the view
    std::string backend = "auto"; // auto | cpu | cuda
    std::array<char, 512> save_path{"live.nbvh"}; // the panel's text field
};

struct ViewSettings {
    int spp_per_frame = 1;     // samples added to the film per displayed frame
    int max_depth = 8;         // path segments (RenderOptions::max_depth)
    int max_samples = 4096;    // accumulation stops here (0: never)
    float exposure = 0.0f;     // stops, display only (does not reset accumulation)
    bool show_ui = true;
    // Neural (only with --model): hybrid render, or the classical reference (triangles).
    bool neural = true;
    int lod = 0;               // primary-ray LoD (0 = finest cut)
    int secondary_lod = -1;    // after the first hit; -1: same as lod
    int max_leaves = 8;        // leaf budget per ray (NeuralRenderOptions::max_rounds, --neural-max-leaves)
    bool override_material = false; // else the assets' glTF materials
    float roughness = 0.5f, metallic = 0.0f;
    // Compare views (with a model).
    ViewMode view = ViewMode::image;
    float split = 0.5f;          // split line, fraction of the film width from the left
    float gain = 4.0f;           // difference view: |a - b| x gain
    int compare_every = 8;       // frames between refreshes of the difference / FLIP image (CPU)
    TrainSettings train;
};

struct PanelInfo {
    std::string scene, device;
    uint32_t width = 0, height = 0;
    uint32_t samples = 0;          // in the film
    double frame_ms = 0.0;         // wall time of the last frame's path tracing
    double rays_per_second = 0.0;  // last frame, GPU time
    uint32_t renderer_builds = 0;  // renderers built (scene upload, pipelines)
    uint32_t live_updates = 0;     // setting changes applied as uploads (no rebuild)
    uint32_t model_swaps = 0;      // models replaced as uploads (same scene and BVHs, no rebuild)
    bool has_model = false;
    std::vector<uint32_t> lod_node_counts; // N-BVH nodes per LoD (index = LoD)
    std::string neural_path;       // MLP kernel in use (hybrid only)
    double neural_queries_per_ray = 0.0;
    std::string status;            // last rebuild error or note
    // Compare views: the classical reference's samples, and the last FLIP of hybrid vs classical.
    uint32_t reference_samples = 0;
    double reference_frame_ms = 0.0;
    double flip_mean = -1.0;       // < 0: not computed yet
    uint32_t flip_samples = 0, flip_reference_samples = 0; // film samples the FLIP was computed at
    // Live training (live_training.h).
    bool can_train = false;        // the scene has neural instances
    std::string train_state;       // "", "running", "paused", "done", "stopped", "failed: ..."
    uint32_t train_step = 0, train_steps = 0, train_nodes = 0;
    double train_loss = 0.0, train_eta_s = 0.0;
    uint32_t train_snapshots = 0;  // models swapped into the view
    std::vector<float> train_loss_history;
    // Loss view (loss_view.h): whether the model shown has per-node losses, and the last image's range.
    bool has_node_loss = false;
    float loss_lo = 0.0f, loss_hi = 0.0f; // colour scale (log), of the leaves seen
    uint32_t loss_leaves = 0;             // distinct leaves seen in the loss view
};

struct PanelActions {
    bool reset_camera = false;
    bool rebuild = false;          // a renderer setting changed (apply now)
    bool reset_accumulation = false;
    bool train_start = false, train_pause = false, train_stop = false;
    std::string train_save;        // save the live-trained model to this path
};

PanelActions draw_panel(ViewSettings& settings, const PanelInfo& info);

// The LoD whose node count is closest to `nodes` (ties: the finer LoD). Empty table: 0.
int lod_for_node_count(const std::vector<uint32_t>& lod_node_counts, uint32_t nodes);

} // namespace nbvh::viewer
