// nbvh study SCENE --out DIR [--nodes N,N,..] [--hash-log2 T,T,..] [--lods L] [--camera C]... [--cameras K]
//                  [--width W --height H --spp S] [--ref-spp R] [--time-spp T --repeat N] [--backend ...]
// What accuracy costs (issue 11): trains every node budget x hash size, renders every level of detail
// from every camera and writes frame time, memory, training time and FLIP against a converged classical
// reference (with the noise floor beside it), next to the equal-memory decimation and equal-time
// classical baselines, as DIR/study.csv and DIR/study.json (scripts/bench/plot_study.py plots them).
#include <memory>
#include <string>

#include "app/build_info.h"
#include "app/commands.h"
#include "app/render_args.h"
#include "app/study/study_runner.h"
#include "engine/vk/context.h"

namespace nbvh::app {

void add_study_command(CLI::App& app, const std::string& command_line) {
    auto o = std::make_shared<StudyOptions>();
    o->command_line = command_line;
    auto* cmd = app.add_subcommand("study",
                                   "sweep node budgets x hash sizes x LoDs over several cameras: frame time, "
                                   "memory, training time and converged FLIP vs baselines (CSV + JSON)");
    cmd->option_defaults()
        ->always_capture_default(); // --help shows the study's defaults (960x540, 256 spp ...)
    cmd->add_option("scene", o->scene, "glTF/GLB file, or 'default' for the built-in scene")->required();
    cmd->add_option("--out", o->out_dir, "output folder (study.json, study.csv; created)")->required();
    cmd->add_option("--neural", o->neural_glob,
                    "glob of node names to make neural (overrides '*_neural' scenes)");
    cmd->add_option("--asset", o->asset_glob, "learn only the neural assets whose name matches this glob");
    cmd->add_option("--nodes", o->nodes,
                    "N-BVH node budgets to train, comma-separated (default: the backend's)")
        ->delimiter(',')
        ->check(CLI::Range(1u, 1u << 26));
    cmd->add_option("--hash-log2", o->hash_log2,
                    "hash-table sizes (log2) to train, comma-separated (default: "
                    "nbvh train's compact default)")
        ->delimiter(',')
        ->check(CLI::Range(4u, 24u));
    cmd->add_option("--lods", o->lods, "levels of detail per model (each one a row)");
    cmd->add_option("--steps", o->steps, "optimiser steps per model (default: the backend's)");
    cmd->add_option("--batch", o->batch, "rays per step (default: the backend's)");
    cmd->add_option("--threads", o->threads, "CPU backend threads (default: all cores)");
    cmd->add_option("--train-seed", o->train_seed, "training seed");
    cmd->add_option("--backend", o->backend, "training backend: cpu, cuda or auto");
    cmd->add_option("--camera", o->cameras, "a camera (ex,ey,ez,tx,ty,tz,fov_deg); repeat for several")
        ->take_all()
        ->allow_extra_args(false);
    cmd->add_option("--cameras", o->camera_count,
                    "cameras in all: the given or scene's one, then orbits around it")
        ->check(CLI::Range(1u, 16u));
    add_render_option_flags(cmd,
                            o->render); // --width --height --spp (compared images) --max-depth --seed ...
    cmd->add_option("--ref-spp", o->ref_spp, "samples per pixel of the classical reference (another seed)")
        ->check(CLI::Range(1u, 1u << 20));
    cmd->add_option("--time-spp", o->time_spp, "samples per pixel of the timed frames")
        ->check(CLI::Range(1u, 4096u));
    cmd->add_option("--repeat", o->repeat, "timed frames per row after a warm-up (the median is reported)")
        ->check(CLI::Range(1u, 1000u));
    cmd->add_option("--time-width", o->time_width, "width of the timed frames (default: --width)")
        ->check(CLI::Range(1u, 16384u));
    cmd->add_option("--time-height", o->time_height, "height of the timed frames (default: --height)")
        ->check(CLI::Range(1u, 16384u));
    cmd->add_option("--device", o->device,
                    std::string(vk::DEVICE_OPTION_HELP) + "; with gpu:N the CUDA trainer uses the same GPU");
    cmd->add_option("--env", o->env, "environment map (.hdr or .exr), or 'none' (the scene's lights only)");
    cmd->add_option("--env-rotation", o->env_rotation, "rotate the environment about +y by this many degrees")
        ->check(CLI::Range(-3600.0f, 3600.0f));
    cmd->add_option("--exposure", o->exposure,
                    "PNG exposure of every compared image: 'auto' (the reference's, per "
                    "camera) or stops");
    cmd->add_option("--neural-path", o->neural_path, "MLP implementation: auto, scalar or coopmat");
    cmd->add_option("--cap-study", o->cap_study, "extra LoD-0 rows with this per-ray leaf budget (0: none)")
        ->check(CLI::Range(0u, 256u));
    cmd->add_flag("!--no-decimation", o->decimation, "skip the equal-memory decimation baseline");
    cmd->add_flag("!--no-equal-time", o->equal_time, "skip the equal-time classical baseline");
    cmd->add_option(
           "--budget-minutes", o->budget_minutes,
           "start no configuration that would end after this many minutes (the rest is reported as not run)")
        ->check(CLI::Range(0.0, 1.0e6));
    cmd->add_option("--references", o->references_dir,
                    "folder that keeps each camera's classical side (reference, noise floor, frame time, "
                    "equal-time FLIPs): taken from it when a study of the same setup made it, else written");
    cmd->add_flag("--references-only", o->references_only,
                  "render the cameras' classical side into --references and stop (no training)");
    cmd->add_option("--reference-cameras", o->reference_cameras,
                    "with --references-only: these cameras only, comma-separated (one GPU each: "
                    "scripts/bench/study_multi.sh)")
        ->delimiter(',')
        ->check(CLI::Range(0u, 15u));
    cmd->add_option("--equal-time-upto", o->equal_time_upto,
                    "extend each camera's classical film to this x --spp up front (equal-time FLIPs of "
                    "hybrids up to this x the classical frame, kept with --references; 0: as rows ask)")
        ->check(CLI::Range(0.0, 64.0));
    cmd->add_flag("--save-images", o->save_images,
                  "also write camera 0's reference, hybrid and decimated PNGs");
    cmd->callback([o] {
        o->commit = build_commit();
        run_study(*o);
    });
}

} // namespace nbvh::app
