// The difference and FLIP views: the hybrid film against the classical reference, both encoded as the
// window shows them (exposure, ACES, 8-bit sRGB: the bytes of `nbvh render`'s PNGs), compared on the
// CPU (engine/core/flip.h, the same LDR-FLIP as `nbvh flip` and `nbvh bench`) on a worker thread, and
// shown as RGBA8 bytes. The films are read back every `compare_every` frames; the window keeps
// showing the last result meanwhile, so a 1080p FLIP (about a second on one core) never stalls a frame.
#pragma once
#include <cstdint>
#include <future>
#include <vector>

#include "app/viewer/ui_panel.h"
#include "engine/core/image.h"

namespace nbvh::render {
class WavefrontRenderer;
}

namespace nbvh::viewer {

struct CompareResult {
    uint32_t width = 0, height = 0;
    std::vector<uint32_t> rgba8;   // packed as the display pass writes (R in the low byte, alpha 255)
    double flip_mean = 0.0;        // LDR-FLIP, hybrid vs classical
    double mean_abs_difference = 0.0; // of the display bytes, in [0, 1]
    uint32_t test_samples = 0, reference_samples = 0;
    ViewMode mode = ViewMode::flip;   // what rgba8 shows (difference or flip)
};

// Pure: the compare image of two display-pixel images of one size (difference: |a - b| in sRGB, x gain;
// flip: the magma heat map) and the means.
CompareResult compare_images(const Image& test, const Image& reference, ViewMode mode, float gain);

class Comparer {
public:
    ~Comparer();
    // Starts a comparison when none runs and `frames_since` >= settings.compare_every (or no result
    // exists yet): both films are read back now, the rest runs on a worker thread. Collects a finished
    // one. Returns true when a new result became available.
    bool update(const render::WavefrontRenderer& test, const render::WavefrontRenderer& reference,
                const ViewSettings& settings);
    // Compares the films now and waits for the result (scripts: `compare`; a running job is dropped).
    void refresh_now(const render::WavefrontRenderer& test, const render::WavefrontRenderer& reference,
                     const ViewSettings& settings);
    // Forgets the result (scene, size or settings changed); a running job's result is discarded.
    void invalidate();
    bool has_result() const { return result_.width > 0; }
    const CompareResult& result() const { return result_; }
    bool busy() const { return job_.valid(); }

private:
    void start(const render::WavefrontRenderer& test, const render::WavefrontRenderer& reference,
               const ViewSettings& settings);
    std::future<CompareResult> job_;
    CompareResult result_;
    uint64_t generation_ = 0, job_generation_ = 0;
    uint32_t frames_since_ = 0;
};

} // namespace nbvh::viewer
