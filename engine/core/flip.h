// FLIP image difference (NVIDIA ꟻLIP, Andersson et al. 2020, "FLIP: A Difference Evaluator for
// Alternating Images"; HDR-FLIP: Andersson et al. 2021), re-implemented from the description in
// ../shared/reference/flip.md so that its mean matches the official FLIP v1.6 tool to 5e-5.
//
// LDR-FLIP takes linear RGB in [0,1] (an 8-bit sRGB PNG loaded with load_image() is already decoded);
// HDR-FLIP takes linear RGB of any range (EXR) and brackets exposures from the reference.
// Everything is float32; all filters are separable correlations (x then y) with clamp-to-edge borders.
// Images may have 3 or 4 channels (alpha is ignored); reference and test must have the same size.
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "engine/core/image.h"

namespace nbvh {

// Pixels per degree of the assumed viewer: distance · (resX / width) · π/180 (flip.md §4).
// Defaults: a 0.7 m wide 4K monitor seen from 0.7 m -> 67.0206 ppd.
float flip_ppd(float distance_m = 0.7f, float monitor_width_m = 0.7f, float resolution_x = 3840.0f);

struct FlipResult {
    int width = 0, height = 0;
    std::vector<float> error; // per-pixel FLIP in [0,1], row-major, top row first
    float mean = 0.0f;        // Σ error / pixel count, accumulated in float row by row (as the tool)
    // HDR-FLIP only: the exposure range used and, per pixel, i/(N-1) of the exposure that gave the max.
    int exposure_count = 0;
    float start_exposure = 0.0f, stop_exposure = 0.0f;
    std::vector<float> exposure_map;
};

FlipResult flip_ldr(const Image& reference, const Image& test, float ppd = flip_ppd());

// One reference prepared once (colour transforms, CSF and feature filters) for LDR-FLIP against many test
// images: flip_ldr(reference, test, ppd) is FlipReference(reference, ppd).compare(test); a kept one
// filters one image per comparison instead of two (the study and `nbvh converge` compare each reference
// with every row's image). Copies share the prepared planes; the reference image itself is not kept.
struct FlipPrepared;
struct FlipKernels;
class FlipReference {
  public:
    explicit FlipReference(const Image& reference, float ppd = flip_ppd());
    FlipResult compare(const Image& test) const;
    int width() const { return width_; }
    int height() const { return height_; }

  private:
    int width_ = 0, height_ = 0;
    std::shared_ptr<const FlipKernels> kernels_;
    std::shared_ptr<const FlipPrepared> prepared_;
};

// HDR-FLIP tone mappers (flip.md §6.4).
enum class FlipToneMapper { aces, hable, reinhard };

struct HdrFlipOptions {
    FlipToneMapper tone_mapper = FlipToneMapper::aces;
    std::optional<float> start_exposure; // stops; computed from the reference when absent
    std::optional<float> stop_exposure;
};

FlipResult flip_hdr(const Image& reference, const Image& test, float ppd = flip_ppd(),
                    const HdrFlipOptions& options = {});

// ---- pieces exposed for tests and tools -------------------------------------------------------

// The rational curve coefficients k0..k5 of T(x) = (k0 x² + k1 x + k2)/(k3 x² + k4 x + k5).
// (Reinhard's entry is the one used for the exposure computation only.)
const float* flip_tone_map_coefficients(FlipToneMapper tm);
// Larger root of T(x) = 0.85 (the input that tone-maps to 0.85).
float flip_tone_map_x_max(FlipToneMapper tm);
// Applies the tone mapper to one linear RGB triple in place (no clamp).
void flip_tone_map(FlipToneMapper tm, float rgb[3]);

struct FlipExposureRange {
    float start = 0.0f, stop = 0.0f; // stops
    int count = 2;                   // N = max(2, ceil(stop - start))
};
// From the reference luminances: start = log2(x_max / Y_max), stop = log2(x_max / Y_median), with
// Y_median the element at index N/2 after sorting. Degenerate references (no positive luminance)
// throw Error; a zero median falls back to the smallest positive luminance and N is capped at 64.
FlipExposureRange flip_exposure_range(const Image& reference, FlipToneMapper tm);

struct FlipKernels {
    int csf_radius = 0;              // ceil(3·sqrt(0.04/(2π²))·PPD)
    std::vector<float> y, cx;        // 1-D CSF kernels, each sums to 1
    std::vector<float> cz1, cz2;     // separable halves of the two Cz Gaussians, scaled by 1/sqrt(S1²+S2²)
    int feature_radius = 0;          // ceil(3σ), σ = 0.5·0.082·PPD
    float feature_sigma = 0.0f;      // pixels
    std::vector<float> g, dg, ddg;   // Gaussian and its 1st/2nd derivative, normalised per flip.md §6.3
};
FlipKernels flip_kernels(float ppd);

// Magma colour map (matplotlib "magma" sampled at 9 even stops, linearly interpolated in sRGB 8-bit):
// value in [0,1] -> index round(255·v) -> RGB. Returns width*height*3 bytes.
std::vector<uint8_t> flip_heatmap_rgb8(const FlipResult& result);
void save_flip_heatmap(const std::string& path, const FlipResult& result);

} // namespace nbvh
