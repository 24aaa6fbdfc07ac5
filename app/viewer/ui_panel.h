// The viewer's Dear ImGui panel: what the user can change (ViewSettings, owned by the viewer) and
// what it shows (PanelInfo). Settings that the path tracer bakes into its pipelines and buffers
// (max depth, LoDs, neural on/off, neural material constants) are applied when a slider is released,
// so dragging does not rebuild the renderer every frame.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace nbvh::viewer {

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
    bool override_material = false; // else the assets' glTF materials
    float roughness = 0.5f, metallic = 0.0f;
};

struct PanelInfo {
    std::string scene, device;
    uint32_t width = 0, height = 0;
    uint32_t samples = 0;          // in the film
    double frame_ms = 0.0;         // wall time of the last frame's path tracing
    double rays_per_second = 0.0;  // last frame, GPU time
    uint32_t renderer_builds = 0;  // renderers built (scene upload, pipelines)
    uint32_t live_updates = 0;     // setting changes applied as uploads (no rebuild)
    bool has_model = false;
    std::vector<uint32_t> lod_node_counts; // N-BVH nodes per LoD (index = LoD)
    std::string neural_path;       // MLP kernel in use (hybrid only)
    double neural_queries_per_ray = 0.0;
    std::string status;            // last rebuild error or note
};

struct PanelActions {
    bool reset_camera = false;
    bool rebuild = false;          // a renderer setting changed (apply now)
    bool reset_accumulation = false;
};

PanelActions draw_panel(ViewSettings& settings, const PanelInfo& info);

// The LoD whose node count is closest to `nodes` (ties: the finer LoD). Empty table: 0.
int lod_for_node_count(const std::vector<uint32_t>& lod_node_counts, uint32_t nodes);

} // namespace nbvh::viewer
