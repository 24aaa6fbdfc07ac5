// CPU float images: loading (PNG/JPG/HDR via stb_image, EXR via tinyexr), saving (PNG via
// stb_image_write with an sRGB encode, EXR via tinyexr) and small helpers.
//
// Pixels are always *linear* RGB(A) float32, row-major, top row first. 8-bit inputs (PNG/JPG) are
// decoded from sRGB with the exact piecewise sRGB curve (the one FLIP uses, flip.md §6.1), so an
// LDR image loaded here can go straight into flip_ldr(). Alpha, when present, is stored unchanged
// (linear, v/255).
//
// Unreadable files, unknown extensions and empty images throw nbvh::Error with one line.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace nbvh {

struct Image {
    int width = 0, height = 0;
    int channels = 4;        // 1, 3 or 4 (loaders always produce 4: RGBA, alpha 1 when absent)
    std::vector<float> data; // width*height*channels, linear

    Image() = default;
    Image(int w, int h, int c, float fill = 0.0f);
    bool empty() const { return width <= 0 || height <= 0 || data.empty(); }
    size_t pixel_count() const { return size_t(width) * size_t(height); }
    float* at(int x, int y) { return data.data() + (size_t(y) * width + x) * channels; }
    const float* at(int x, int y) const { return data.data() + (size_t(y) * width + x) * channels; }
};

// How a linear image is mapped to display values before sRGB encoding (save_png / to_srgb8).
enum class ToneMap {
    clamp,    // just clamp to [0,1] (default: renders are compared as-is)
    aces,     // Narkowicz ACES fit applied to 0.6*x (same curve as HDR-FLIP's default, flip.md §6.4)
    reinhard, // luminance-based rgb / (1 + L)
};

struct PngEncode {
    float exposure = 0.0f;   // stops: values are multiplied by 2^exposure first
    ToneMap tone_map = ToneMap::clamp;
    bool keep_alpha = false; // write RGBA when the image has 4 channels, else RGB
};

// The exact sRGB transfer functions (IEC 61966-2-1), float32.
float srgb_to_linear(float c);
float linear_to_srgb(float c);

// Per-channel (aces) or per-pixel (reinhard) tone map of an RGB triple, in place; clamp does nothing.
void tone_map_rgb(ToneMap tm, float rgb[3]);
// The tone map's id in shaders/shared/display.h (NB_TONE_MAP_*), for GPU passes.
uint32_t tone_map_id(ToneMap tm);
ToneMap parse_tone_map(const std::string& name); // "clamp", "aces", "reinhard"; throws Error otherwise

// Loading: picks the decoder by extension (.png .jpg .jpeg .bmp .tga -> 8-bit sRGB; .hdr -> linear;
// .exr -> linear via tinyexr). Result has 4 channels.
Image load_image(const std::string& path);
bool is_exr_path(const std::string& path);  // case-insensitive extension test
bool is_png_path(const std::string& path);

// Encodes to 8-bit sRGB (3 or 4 channels per pixel per `enc.keep_alpha`), non-finite values -> 0.
std::vector<uint8_t> to_srgb8(const Image& img, const PngEncode& enc, int* out_channels = nullptr);
void save_png(const std::string& path, const Image& img, const PngEncode& enc = {});
// `linear` as a PNG of `nbvh render` holds it (exposure in stops, ACES tone map, 8-bit sRGB), decoded back
// to linear [0,1] RGB: what flip_ldr compares (`nbvh flip a.png b.png`), and what the viewer shows.
Image as_png_pixels(const Image& linear, float exposure_stops = 0.0f);
// Writes already-encoded 8-bit pixels (channels 1..4). Used for heatmaps (colour maps are sRGB).
void save_png_8bit(const std::string& path, int width, int height, int channels, const uint8_t* pixels);
// Linear float EXR (RGB or RGBA as the image has; 1-channel is written as Y). half=true stores fp16.
void save_exr(const std::string& path, const Image& img, bool half = false);

// Number of NaN/Inf samples (all channels).
size_t count_non_finite(const Image& img);
// Replaces NaN and -Inf by 0, +Inf by `max_value`; returns how many samples changed.
size_t sanitize_non_finite(Image& img, float max_value = 65504.0f);

// Copy with `channels` channels (drops alpha, or adds alpha=1 / replicates a grey channel).
Image convert_channels(const Image& img, int channels);

} // namespace nbvh
