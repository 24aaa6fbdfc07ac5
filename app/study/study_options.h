// What `nbvh study` measures (issue 11): the sweep (node budgets x hash sizes, every level of detail),
// the cameras, the image settings and the baselines.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "engine/render/wavefront.h"

namespace nbvh::app {

// The seed of a study's (and `nbvh converge`'s) classical reference is the compared images' seed plus this:
// any other seed would do, the reference's noise must be independent of theirs.
inline constexpr uint32_t STUDY_REFERENCE_SEED_OFFSET = 1000003;

struct StudyOptions {
    std::string scene, neural_glob, asset_glob, out_dir;
    std::string env, device = "auto", backend = "auto", exposure = "auto";
    std::optional<float> env_rotation; // degrees
    std::string command_line, commit;  // written into the results

    // Sweep: every node budget x every hash size is trained once (empty: the backend's default, one value).
    std::vector<uint32_t> nodes, hash_log2;
    uint32_t lods = 3; // levels of detail per model: each is a row
    std::optional<uint32_t> steps, batch;
    uint32_t threads = 0;
    uint64_t train_seed = 1337;

    // Cameras: the --camera ones, then the scene's (or auto-framed) one, then orbits around its target up
    // to `camera_count` (study_cameras.h).
    std::vector<std::string> cameras;
    uint32_t camera_count = 3;

    // Images. render.spp is the spp of every compared image (hybrid, noise floor, decimated); the
    // reference has ref_spp with another seed; frame times are medians of `repeat` renders at time_spp.
    render::RenderOptions render;
    uint32_t ref_spp = 1024, time_spp = 4, repeat = 3;
    uint32_t time_width = 0, time_height = 0; // frame times at another size (0: the image size)
    std::string neural_path = "auto";
    uint32_t cap_study = 64; // extra LoD-0 rows with this per-ray leaf budget (0: none)
    bool decimation = true;  // equal-memory meshoptimizer baseline rows
    bool equal_time = true;  // classical at the spp that fits the hybrid's frame time
    bool save_images = false;
    // The classical side of every camera (reference, noise floor, frame time, equal-time FLIPs) kept in
    // this folder and taken from it when a study of the same setup made it (study_references.h).
    std::string references_dir;
    bool references_only = false;            // write the cameras' classical side there and stop (no sweep)
    std::vector<uint32_t> reference_cameras; // with references_only: these cameras only (default: all)
    // Extend each camera's classical film to this x spp up front, so equal-time FLIPs of hybrids up to
    // this x the classical frame time are kept with the references (0: as the rows ask for them).
    double equal_time_upto = 0.0;
    double budget_minutes = 0.0; // > 0: start no configuration that would end past this (wall time) //
                                 // reference / hybrid / decimated PNGs of camera 0 (first config)

    StudyOptions() {
        render.width = 960;
        render.height = 540;
        render.spp = 256;
    }
};

} // namespace nbvh::app
