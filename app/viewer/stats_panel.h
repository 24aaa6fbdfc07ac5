// The viewer's stats window (issue 13 "Stats panel"): per-pass GPU times of the last frame of each
// renderer, rays/s, neural queries per ray and per second, the model's memory against the meshes + BLAS
// it replaces (compression), leaf-cap hits (path rays that spent their whole leaf budget, counted on the
// GPU: RenderStats::neural_leaf_cap_rays), the FLIP of the hybrid view against the classical reference,
// and the build / setting-change / model-swap counters; and the same numbers as JSON for scripts
// (`report`).
#pragma once
#include <nlohmann/json.hpp>

#include "app/viewer/ui_panel.h"
#include "app/viewer/viewer_scene.h"
#include "engine/render/wavefront.h"

namespace nbvh::viewer {

struct StatsView {
    const PanelInfo* info = nullptr;
    const ViewSettings* settings = nullptr;
    const render::RenderStats* main = nullptr;      // last frame of the main renderer
    const render::RenderStats* reference = nullptr; // of the classical reference (compare views), else null
    NeuralMemory memory;
    uint32_t reference_builds = 0;
};

// Draws the window (placed right of the panel); nothing when `show` is false.
void draw_stats_panel(const StatsView& view);

// Everything a test or a measurement needs: counters, samples, frame times, per-pass GPU ms, memory,
// FLIP, training, status.
nlohmann::json stats_json(const StatsView& view);

} // namespace nbvh::viewer
