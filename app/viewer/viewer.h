// nbvh view: the interactive viewer (window + swapchain + Dear ImGui over the wavefront path
// tracer, accumulating samples progressively; app/README.md). The viewer owns UI state
// (viewer_session.h); settings reach the renderer as uploads (WavefrontRenderer::apply).
#pragma once
#include <cstdint>
#include <string>

#include "engine/render/neural_stage.h"

namespace nbvh::viewer {

struct ViewerArgs {
    std::string scene;            // glTF/GLB file or "default"
    std::string model;            // .nbvh for the scene's neural instances (hybrid render)
    std::string env;              // --env FILE | none | "" (app/render_args.h choose_environment)
    std::string neural_glob;      // nodes whose name matches are neural instances
    uint32_t subdivide = 0;       // --subdivide L (engine/scene/subdivide.h), as for nbvh render
    std::string device = "auto";  // auto | gpu | cpu
    uint32_t width = 1280, height = 720; // window (and initial film) size
    uint32_t max_depth = 8;
    uint32_t lod = 0;
    int32_t secondary_lod = render::SECONDARY_LOD_COARSEST; // or SECONDARY_LOD_SAME or a LoD index
    std::string screenshot;       // PNG of the window content after `frames` frames
    uint32_t frames = 0;          // > 0: exit after this many frames (headless tests)
    bool hide_ui = false;
    std::string script;           // command file (script.h); the viewer exits when it ends
};

// Runs until the window is closed (or `frames` frames, or the script's end). Throws nbvh::Error on
// user errors (no display, bad scene/model/script), and when Vulkan validation is on and reported
// anything. Errors after the start (a dropped bad file, a failed training) are shown in the window.
void run_viewer(const ViewerArgs& args);

} // namespace nbvh::viewer
