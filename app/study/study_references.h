// `nbvh study --references DIR` (issue 11): the classical side of a study's cameras kept on disk, so a
// later study of the same setup skips its renders: another sweep of the same scene, or the parts of a
// sweep spread over several GPUs (scripts/bench/study_multi.sh renders each camera's side once, on its
// own GPU, with --references-only, before the parts start). Per camera `i` the folder holds
// camera_i.json (what made it, and the figures) and camera_i_reference.png / camera_i_floor.png (the
// reference and the noise-floor render as the FLIPs see them: 8-bit sRGB at the camera's exposure, so a
// loaded camera gives the same FLIPs to the last bit).
//
// What made a camera (its key: scene, camera, environment, image and timing settings, the binary's
// commit, the device and driver) must match the study's, field by field: a folder made by another setup
// is a one-line error naming the first field that differs, never silently reused or overwritten.
#pragma once
#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "engine/core/image.h"

namespace nbvh::app::study {

struct CachedCamera {
    float exposure = 0.0f; // stops of the camera's PNGs
    double noise_floor = 0.0, classical_ms = 0.0;
    std::map<uint32_t, double> equal_time_flip; // classical spp -> FLIP vs the reference (equal-time rows)
    Image reference_px, floor_px;               // as_png_pixels of the reference and the floor render
};

// Camera `index` from `dir`: nullopt when it is not there. Throws nbvh::Error when it was made with
// another key (naming the first field that differs) or its files are unreadable.
std::optional<CachedCamera> load_reference(const std::string& dir, size_t index, const nlohmann::json& key);

// Writes camera `index` to `dir` (created), each file replaced whole (written aside, then renamed).
void save_reference(const std::string& dir, size_t index, const nlohmann::json& key, const CachedCamera& cam);

} // namespace nbvh::app::study
