// Automatic exposure for display images (nbvh render --exposure auto, the default for PNG output): the
// exposure that maps the image's key luminance to middle grey, limited so that its brightest percent stays
// below the tone map's shoulder. EXR output is never scaled.
#pragma once
#include "engine/core/image.h"

namespace nbvh {

struct AutoExposure {
    float stops = 0.0f;    // multiply by 2^stops before the tone map (PngEncode::exposure)
    float key = 0.0f;      // log-average luminance of the lit pixels (0: none)
    float bright = 0.0f;   // their 99th-percentile luminance
    size_t lit_pixels = 0; // finite pixels with luminance > 0 (black background pixels do not count)
};

// The key (log-average luminance over the lit pixels between their 5th and 95th percentiles, so that a few
// very dark or bright pixels do not decide; Reinhard et al. 2002 "Photographic tone reproduction" §2) is
// mapped to AUTO_EXPOSURE_KEY; the 99th percentile is kept at or below AUTO_EXPOSURE_BRIGHT (the ACES fit
// of 0.6 x 12 is 0.98: nearly white). An image without a lit pixel gets 0 stops. Clamped to +-24 stops.
AutoExposure auto_exposure(const Image& linear);

// Reinhard's key value: 0.18 for "normal" scenes, up to 0.36-0.72 for light ones. 0.3 because our ACES fit
// already scales radiance by 0.6 (a key of 0.3 displays at sRGB ~0.55), and it keeps the shared scenes
// under the default sky within 0.3 stops of exposure 0, at which their look was tuned (key 0.25-0.35).
constexpr float AUTO_EXPOSURE_KEY = 0.3f;
constexpr float AUTO_EXPOSURE_BRIGHT = 12.0f;

} // namespace nbvh
