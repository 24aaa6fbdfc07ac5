// nbvh view SCENE [--model M.nbvh] [--env FILE|none] [--width W --height H] [--device auto|gpu|cpu]
//                 [--max-depth D] [--lod L] [--secondary-lod coarsest|same|L] [--neural GLOB] [--subdivide L]
//                 [--screenshot FILE.png] [--frames N] [--hide-ui] [--script FILE]
// The interactive viewer (app/viewer/): progressive path tracing in a window with a UI panel.
// --frames N exits after N frames (headless tests under Xvfb); --screenshot saves the window then;
// --script FILE drives the viewer from a command file (app/viewer/script.h) and exits at its end.
#include <memory>

#include "app/commands.h"
#include "app/render_args.h"
#include "app/viewer/viewer.h"
#include "engine/vk/context.h"

namespace nbvh::app {

void add_view_command(CLI::App& app) {
    auto args = std::make_shared<viewer::ViewerArgs>();
    auto* cmd = app.add_subcommand("view", "interactive viewer: progressive path tracing, LoD and node-count sliders");
    cmd->add_option("scene", args->scene, "glTF/GLB file, or 'default' for the built-in scene")->required();
    cmd->add_option("--model", args->model, "N-BVH model (.nbvh) for the scene's neural instances");
    cmd->add_option("--env", args->env,
                    "environment map (.hdr or .exr, equirectangular), or 'none' (the scene's lights only); default: "
                    "the scene's, else the default sky (as nbvh render)");
    cmd->add_option("--neural", args->neural_glob, "nodes whose name matches this glob are neural instances");
    add_subdivide_option(cmd, args->subdivide);
    cmd->add_option("--width", args->width, "window width in pixels")->check(CLI::Range(16u, 16384u));
    cmd->add_option("--height", args->height, "window height in pixels")->check(CLI::Range(16u, 16384u));
    cmd->add_option("--device", args->device,
                    std::string(vk::DEVICE_OPTION_HELP) +
                        "; with gpu:N live CUDA training uses the same GPU");
    cmd->add_option("--max-depth", args->max_depth, "maximum path segments")->check(CLI::Range(1u, 256u));
    cmd->add_option("--lod", args->lod, "initial N-BVH level of detail (0 = finest)");
    auto secondary_lod = std::make_shared<std::string>("coarsest");
    cmd->add_option("--secondary-lod", *secondary_lod,
                    "initial LoD after the first hit: coarsest (default), same (as --lod) or 0..7 (as nbvh render)");
    cmd->add_option("--screenshot", args->screenshot, "save the window content as PNG after --frames frames");
    auto* frames = cmd->add_option("--frames", args->frames, "exit after this many frames (default with --screenshot: 16)")
                       ->check(CLI::Range(1u, 1u << 20));
    cmd->add_option("--script", args->script, "run the commands of this file (app/viewer/script.h), then exit")
        ->excludes(frames);
    cmd->add_flag("--hide-ui", args->hide_ui, "start with the UI panel hidden (F1 toggles it)");
    cmd->callback([args, secondary_lod] {
        viewer::ViewerArgs a = *args;
        a.secondary_lod = parse_secondary_lod(*secondary_lod);
        if (!a.screenshot.empty() && a.frames == 0 && a.script.empty()) a.frames = 16;
        viewer::run_viewer(a);
    });
}

} // namespace nbvh::app
