// The rows of a study and how they are written (issue 11): study.csv (one line per row and camera, plus
// the mean over the cameras) and study.json (the same rows with everything needed to read them: device,
// driver, commit, command line, settings, cameras, noise floors). scripts/bench/plot_study.py draws the
// plots and the table from study.json.
#pragma once
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace nbvh::app {

// Row kinds: "classical" (the true scene at the compared spp: its FLIP is the noise floor), "lod" (a
// model at one level of detail for every ray), "switch" (LoD 0 for camera rays, the coarsest after the
// first hit), "cap" (LoD 0 with another per-ray leaf budget), "decimated" (the neural meshes simplified
// to the model's bytes, rendered classically).
struct StudyRow {
    int config = -1; // index into the configurations (-1: classical rows)
    std::string variant;
    int camera = 0; // -1: mean over the cameras
    uint32_t nodes_target = 0, hash_log2 = 0, lods = 0;
    int lod = -1, secondary_lod = -1;
    uint32_t max_leaves = 0;     // per-ray leaf budget (neural rows)
    uint32_t nodes = 0;          // N-BVH nodes of the row's cut (all assets)
    uint64_t memory_bytes = 0;   // neural: the model with this cut only; decimated / classical: meshes + BLAS
    uint64_t resident_bytes = 0; // neural: every LoD, as a hybrid render holds it
    uint64_t triangles = 0;      // decimated / classical: triangles of the neural meshes
    double compression = NAN;    // the full neural meshes + BLAS / memory_bytes
    double frame_ms = NAN;       // GPU ms of one frame at time_spp (median)
    double classical_frame_ms = NAN; // the same for the true scene, same camera
    double ratio_to_classical = NAN;
    double flip = NAN;             // LDR-FLIP vs the converged classical reference
    double noise_floor = NAN;      // FLIP of the classical render (same spp, other seed) vs the reference
    double flip_same_seed = NAN;   // vs the classical render with the same seed and spp
    double flip_vs_base_cap = NAN; // cap rows: vs LoD 0 at the default leaf budget, same seed and spp
    bool within_2x_floor = false;  // flip <= 2 x noise floor: not distinguishable from noise
    bool converged = false;        // noise floor <= flip / 3, or <= 0.005 (the criterion)
    double queries_per_ray = NAN;
    double leaf_cap_fraction = NAN; // neural rows: rays (path and shadow) at their leaf budget / all rays
    uint32_t equal_time_spp = 0; // classical spp in the hybrid's frame time
    double equal_time_flip = NAN;
    double train_seconds = NAN, final_loss = NAN;
    bool decimation_sloppy = false;
};

// Marks within_2x_floor and converged from flip and noise_floor.
void mark_floor(StudyRow& r);

// The mean over cameras of each (config, variant, lod, secondary, leaf budget) group of `rows` (camera >= 0).
std::vector<StudyRow> mean_over_cameras(const std::vector<StudyRow>& rows);

std::string study_csv(const std::vector<StudyRow>& rows, const std::string& scene);
nlohmann::json row_json(const StudyRow& r);
// The CSV header (column names, in order).
std::vector<std::string> study_csv_columns();

} // namespace nbvh::app
