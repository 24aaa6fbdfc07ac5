#include "app/viewer/compare.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "engine/core/flip.h"
#include "engine/render/wavefront.h"

namespace nbvh::viewer {

CompareResult compare_images(const Image& test, const Image& reference, ViewMode mode, float gain) {
    NBVH_CHECK(test.width == reference.width && test.height == reference.height && test.channels == 3 &&
               reference.channels == 3);
    CompareResult r;
    r.width = uint32_t(test.width);
    r.height = uint32_t(test.height);
    const size_t n = test.pixel_count();
    r.rgba8.resize(n);
    const FlipResult flip = flip_ldr(reference, test);
    r.flip_mean = flip.mean;
    double sum = 0.0;
    const std::vector<uint8_t> heat = mode == ViewMode::flip ? flip_heatmap_rgb8(flip) : std::vector<uint8_t>();
    for (size_t i = 0; i < n; ++i) {
        uint32_t rgb[3];
        for (int c = 0; c < 3; ++c) {
            // The difference of what the window shows (sRGB-encoded), not of linear radiance.
            const float a = linear_to_srgb(test.data[i * 3 + size_t(c)]);
            const float b = linear_to_srgb(reference.data[i * 3 + size_t(c)]);
            const float d = std::fabs(a - b);
            sum += d;
            rgb[c] = mode == ViewMode::flip ? heat[i * 3 + size_t(c)]
                                            : uint32_t(std::lround(std::min(1.0f, d * gain) * 255.0f));
        }
        r.rgba8[i] = rgb[0] | (rgb[1] << 8) | (rgb[2] << 16) | 0xFF000000u;
    }
    r.mean_abs_difference = n ? sum / double(3 * n) : 0.0;
    r.mode = mode;
    return r;
}

Comparer::~Comparer() {
    if (job_.valid()) job_.wait();
}

void Comparer::invalidate() {
    result_ = CompareResult{};
    generation_++;
    frames_since_ = 0;
}

bool Comparer::update(const render::WavefrontRenderer& test, const render::WavefrontRenderer& reference,
                      const ViewSettings& s) {
    bool fresh = false;
    if (job_.valid() && job_.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
        CompareResult r = job_.get();
        if (job_generation_ == generation_) {
            result_ = std::move(r);
            fresh = true;
        }
    }
    frames_since_++;
    const bool due = !has_result() || frames_since_ >= uint32_t(std::max(1, s.compare_every));
    if (job_.valid() || !due || test.accumulated_samples() == 0 || reference.accumulated_samples() == 0 ||
        test.width() != reference.width() || test.height() != reference.height())
        return fresh;
    start(test, reference, s);
    return fresh;
}

void Comparer::refresh_now(const render::WavefrontRenderer& test, const render::WavefrontRenderer& reference,
                           const ViewSettings& s) {
    invalidate(); // a running job belongs to the old generation: its result is dropped
    if (job_.valid()) job_.wait();
    job_ = {};
    if (test.accumulated_samples() == 0 || reference.accumulated_samples() == 0) return;
    start(test, reference, s);
    result_ = job_.get();
}

void Comparer::start(const render::WavefrontRenderer& test, const render::WavefrontRenderer& reference,
                     const ViewSettings& s) {
    frames_since_ = 0;
    job_generation_ = generation_;
    // Read back now (the renderers' films change next frame); encode and compare on the worker.
    Image a = test.read_output(), b = reference.read_output();
    const uint32_t sa = test.accumulated_samples(), sb = reference.accumulated_samples();
    const ViewMode mode = s.view;
    const float exposure = s.exposure, gain = s.gain;
    job_ = std::async(std::launch::async, [a = std::move(a), b = std::move(b), sa, sb, mode, exposure, gain] {
        CompareResult r = compare_images(as_png_pixels(a, exposure), as_png_pixels(b, exposure), mode, gain);
        r.test_samples = sa;
        r.reference_samples = sb;
        return r;
    });
}

} // namespace nbvh::viewer
