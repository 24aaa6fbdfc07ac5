// Display encoding of linear HDR radiance: exposure, tone map, sRGB encoding, 8-bit quantisation. The
// one definition for the host's PNG output (engine/core/image.cpp to_srgb8) and the viewer's GPU pass
// (passes/display.comp), so that the window shows exactly the bytes `nbvh render` writes to a PNG.
#ifndef NB_DISPLAY_H
#define NB_DISPLAY_H
#include "compat.h"

#if defined(NB_GLSL)
#define nb_isnan(x) isnan(x)
#define nb_isinf(x) isinf(x)
#elif defined(NB_CUDA)
NB_FN bool nb_isnan(float x) { return isnan(x); }
NB_FN bool nb_isinf(float x) { return isinf(x); }
#else
NB_FN bool nb_isnan(float x) { return std::isnan(x); }
NB_FN bool nb_isinf(float x) { return std::isinf(x); }
#endif

#define NB_TONE_MAP_CLAMP 0u
#define NB_TONE_MAP_ACES 1u     // Narkowicz ACES fit applied to 0.6*x (HDR-FLIP's default, flip.md §6.4)
#define NB_TONE_MAP_REINHARD 2u // per pixel, on luminance

NB_FN float nb_linear_to_srgb(float c) {
    return c <= 0.0031308f ? c * 12.92f : 1.055f * pow(c, 1.0f / 2.4f) - 0.055f;
}

// (k0 x² + k1 x + k2) / (k3 x² + k4 x + k5), k from flip.md §6.4.
NB_FN float nb_tone_map_aces(float x) {
    float x2 = x * x;
    return (x2 * (0.36f * 2.51f) + x * (0.6f * 0.03f)) / (x2 * (0.36f * 2.43f) + x * (0.6f * 0.59f) + 0.14f);
}

// Tone map of an RGB triple (already scaled by the exposure): per channel (aces) or per pixel (reinhard).
NB_FN vec3 nb_tone_map(uint tone_map, vec3 c) {
    if (tone_map == NB_TONE_MAP_ACES) return vec3(nb_tone_map_aces(c.x), nb_tone_map_aces(c.y), nb_tone_map_aces(c.z));
    if (tone_map == NB_TONE_MAP_REINHARD) {
        float l = 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
        return c * (1.0f / (1.0f + max(l, 0.0f)));
    }
    return c;
}

// [0, 1] -> 0..255, rounding half away from zero; NaN (and anything not finite) -> 0.
NB_FN uint nb_display_byte(float v) {
    if (nb_isnan(v) || nb_isinf(v)) v = 0.0f;
    return uint(floor(clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f));
}

// A linear pixel's display bytes: NaN channels count as 0, +Inf as very bright (white), the exposure
// scale `scale` = 2^exposure applied before the tone map, then sRGB encoding of the clamped result.
NB_FN uvec3 nb_display_rgb8(vec3 linear, float scale, uint tone_map) {
    vec3 c;
    c.x = min((nb_isnan(linear.x) ? 0.0f : linear.x) * scale, 3.0e38f);
    c.y = min((nb_isnan(linear.y) ? 0.0f : linear.y) * scale, 3.0e38f);
    c.z = min((nb_isnan(linear.z) ? 0.0f : linear.z) * scale, 3.0e38f);
    c = nb_tone_map(tone_map, c);
    return uvec3(nb_display_byte(nb_linear_to_srgb(clamp(c.x, 0.0f, 1.0f))),
                 nb_display_byte(nb_linear_to_srgb(clamp(c.y, 0.0f, 1.0f))),
                 nb_display_byte(nb_linear_to_srgb(clamp(c.z, 0.0f, 1.0f))));
}

#endif // NB_DISPLAY_H
