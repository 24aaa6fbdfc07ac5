#include "engine/core/exposure.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace nbvh {

AutoExposure auto_exposure(const Image& img) {
    AutoExposure a;
    if (img.empty() || img.channels < 3) return a;
    std::vector<float> lum;
    lum.reserve(img.pixel_count());
    for (size_t i = 0; i < img.pixel_count(); ++i) {
        const float* p = img.data.data() + i * size_t(img.channels);
        const float l = 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2];
        if (std::isfinite(l) && l > 0.0f) lum.push_back(l);
    }
    a.lit_pixels = lum.size();
    if (lum.empty()) return a;
    std::sort(lum.begin(), lum.end());
    const size_t n = lum.size();
    const size_t lo = n * 5 / 100, hi = std::max(lo + 1, n * 95 / 100);
    double sum_log = 0.0;
    for (size_t i = lo; i < hi; ++i) sum_log += std::log2(double(lum[i]));
    a.key = float(std::exp2(sum_log / double(hi - lo)));
    a.bright = lum[std::min(n - 1, n * 99 / 100)];
    float stops = std::log2(AUTO_EXPOSURE_KEY / a.key);
    stops = std::min(stops, std::log2(AUTO_EXPOSURE_BRIGHT / a.bright));
    a.stops = std::isfinite(stops) ? std::clamp(stops, -24.0f, 24.0f) : 0.0f;
    return a;
}

} // namespace nbvh
