#include "engine/core/image.h"

#include "shaders/shared/display.h"
#include "shaders/shared/sampling.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include <unistd.h>

// Debian's libstb (and libtinyexr) ship the implementations compiled: include the headers only,
// never define STB_IMAGE_IMPLEMENTATION / TINYEXR_IMPLEMENTATION here.
#include <stb_image.h>
#include <stb_image_write.h>
#include <tinyexr.h>

#include "engine/core/error.h"
#include "engine/core/log.h"

namespace nbvh {
namespace {

// Refuse absurd sizes before allocating (a corrupt header must not become a huge allocation).
constexpr int64_t MAX_PIXELS = int64_t(1) << 28;

std::string lower_extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

// Writes through `write(tmp)` into a temporary file beside `path`, then renames it into place, so a
// failed or interrupted write never leaves a truncated image where the user's file was (rename within
// one directory is atomic on POSIX). The temporary keeps the extension-free suffix ".tmp<pid>".
template <class WriteFn>
void write_atomically(const std::string& path, const char* kind, WriteFn&& write) {
    const std::string tmp = path + strfmt(".tmp%ld", long(::getpid()));
    std::error_code ec;
    try {
        write(tmp);
    } catch (...) {
        std::filesystem::remove(tmp, ec);
        throw;
    }
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
        std::filesystem::remove(tmp, ec);
        throw Error(strfmt("cannot write %s '%s': %s", kind, path.c_str(), ec.message().c_str()));
    }
}

void check_size(const std::string& path, int w, int h) {
    if (w <= 0 || h <= 0 || int64_t(w) * int64_t(h) > MAX_PIXELS)
        throw Error(strfmt("image '%s' has an unsupported size %dx%d", path.c_str(), w, h));
}

Image load_exr(const std::string& path) {
    float* rgba = nullptr;
    int w = 0, h = 0;
    const char* err = nullptr;
    const int rc = LoadEXR(&rgba, &w, &h, path.c_str(), &err);
    if (rc != TINYEXR_SUCCESS) {
        const std::string msg = err ? err : "unknown error";
        if (err) FreeEXRErrorMessage(err);
        std::free(rgba);
        throw Error(strfmt("cannot read EXR '%s': %s", path.c_str(), msg.c_str()));
    }
    try {
        check_size(path, w, h);
    } catch (...) {
        std::free(rgba);
        throw;
    }
    Image img;
    img.width = w;
    img.height = h;
    img.channels = 4;
    img.data.assign(rgba, rgba + size_t(w) * size_t(h) * 4);
    std::free(rgba);
    return img;
}

Image load_stb(const std::string& path, bool hdr) {
    int w = 0, h = 0, comp = 0;
    if (!stbi_info(path.c_str(), &w, &h, &comp))
        throw Error(strfmt("cannot read image '%s': %s", path.c_str(),
                           stbi_failure_reason() ? stbi_failure_reason() : "unknown format"));
    check_size(path, w, h);
    Image img;
    img.width = w;
    img.height = h;
    img.channels = 4;
    const size_t n = size_t(w) * size_t(h) * 4;
    if (hdr) {
        float* px = stbi_loadf(path.c_str(), &w, &h, &comp, 4);
        if (!px) throw Error(strfmt("cannot decode '%s': %s", path.c_str(), stbi_failure_reason()));
        img.data.assign(px, px + n);
        stbi_image_free(px);
    } else {
        stbi_uc* px = stbi_load(path.c_str(), &w, &h, &comp, 4);
        if (!px) throw Error(strfmt("cannot decode '%s': %s", path.c_str(), stbi_failure_reason()));
        // Table of the 256 decoded values: identical to decoding each v/255 with the formula.
        float lut[256];
        for (int v = 0; v < 256; ++v) lut[v] = std::clamp(srgb_to_linear(float(v) / 255.0f), 0.0f, 1.0f);
        img.data.resize(n);
        for (size_t i = 0; i < n; i += 4) {
            for (int c = 0; c < 3; ++c) img.data[i + c] = lut[px[i + c]];
            img.data[i + 3] = float(px[i + 3]) / 255.0f;
        }
        stbi_image_free(px);
    }
    return img;
}

} // namespace

Image::Image(int w, int h, int c, float fill) : width(w), height(h), channels(c) {
    NBVH_CHECK(w >= 0 && h >= 0 && c >= 1 && c <= 4);
    data.assign(size_t(w) * size_t(h) * size_t(c), fill);
}

// The GPU's decode (shaders/shared/sampling.h) is the one definition; CPU texture sampling, image loading
// and FLIP's LDR input all go through it.
float srgb_to_linear(float c) { return nb_srgb_to_linear(c); }

float linear_to_srgb(float c) { return nb_linear_to_srgb(c); }

uint32_t tone_map_id(ToneMap tm) {
    switch (tm) {
    case ToneMap::clamp: return NB_TONE_MAP_CLAMP;
    case ToneMap::aces: return NB_TONE_MAP_ACES;
    case ToneMap::reinhard: return NB_TONE_MAP_REINHARD;
    }
    return NB_TONE_MAP_CLAMP;
}

void tone_map_rgb(ToneMap tm, float rgb[3]) {
    const vec3 c = nb_tone_map(tone_map_id(tm), vec3(rgb[0], rgb[1], rgb[2]));
    rgb[0] = c.x;
    rgb[1] = c.y;
    rgb[2] = c.z;
}

ToneMap parse_tone_map(const std::string& name) {
    if (name == "clamp" || name == "none") return ToneMap::clamp;
    if (name == "aces") return ToneMap::aces;
    if (name == "reinhard") return ToneMap::reinhard;
    throw Error(strfmt("unknown tone map '%s' (expected clamp, aces or reinhard)", name.c_str()));
}

bool is_exr_path(const std::string& path) { return lower_extension(path) == ".exr"; }
bool is_png_path(const std::string& path) { return lower_extension(path) == ".png"; }

Image load_image(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        throw Error(strfmt("image file '%s' does not exist or is not a file", path.c_str()));
    const std::string ext = lower_extension(path);
    if (ext == ".exr") return load_exr(path);
    if (ext == ".hdr") return load_stb(path, true);
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tga")
        return load_stb(path, false);
    throw Error(strfmt("image '%s': unsupported extension '%s' (png, jpg, bmp, tga, hdr, exr)",
                       path.c_str(), ext.c_str()));
}

std::vector<uint8_t> to_srgb8(const Image& img, const PngEncode& enc, int* out_channels) {
    NBVH_CHECK(img.channels >= 1 && img.channels <= 4);
    const int out_c = (enc.keep_alpha && img.channels == 4) ? 4 : 3;
    if (out_channels) *out_channels = out_c;
    const float scale = std::exp2(enc.exposure);
    const uint32_t tm = tone_map_id(enc.tone_map);
    std::vector<uint8_t> out(img.pixel_count() * size_t(out_c));
    for (size_t i = 0; i < img.pixel_count(); ++i) {
        const float* p = img.data.data() + i * size_t(img.channels);
        const vec3 linear(p[0], p[img.channels >= 3 ? 1 : 0], p[img.channels >= 3 ? 2 : 0]);
        const uvec3 b = nb_display_rgb8(linear, scale, tm); // shaders/shared/display.h (the viewer's GPU pass too)
        for (int c = 0; c < 3; ++c) out[i * out_c + c] = uint8_t(b[c]);
        if (out_c == 4) out[i * out_c + 3] = uint8_t(nb_display_byte(p[3]));
    }
    return out;
}

Image as_png_pixels(const Image& linear, float exposure_stops) {
    PngEncode enc;
    enc.tone_map = ToneMap::aces;
    enc.exposure = exposure_stops;
    int channels = 0;
    const std::vector<uint8_t> px = to_srgb8(linear, enc, &channels);
    Image out(linear.width, linear.height, 3);
    for (size_t i = 0; i < linear.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c)
            out.data[i * 3 + size_t(c)] = srgb_to_linear(float(px[i * size_t(channels) + size_t(c)]) / 255.0f);
    return out;
}

void save_png_8bit(const std::string& path, int width, int height, int channels, const uint8_t* pixels) {
    NBVH_CHECK(width > 0 && height > 0 && channels >= 1 && channels <= 4);
    write_atomically(path, "PNG", [&](const std::string& tmp) {
        if (!stbi_write_png(tmp.c_str(), width, height, channels, pixels, width * channels))
            throw Error(strfmt("cannot write PNG '%s' (does its directory exist and is it writable?)", path.c_str()));
    });
}

void save_png(const std::string& path, const Image& img, const PngEncode& enc) {
    if (img.empty()) throw Error(strfmt("cannot write PNG '%s': empty image", path.c_str()));
    int c = 3;
    const std::vector<uint8_t> px = to_srgb8(img, enc, &c);
    save_png_8bit(path, img.width, img.height, c, px.data());
}

void save_exr(const std::string& path, const Image& img, bool half) {
    if (img.empty()) throw Error(strfmt("cannot write EXR '%s': empty image", path.c_str()));
    NBVH_CHECK(img.channels == 1 || img.channels == 3 || img.channels == 4);
    write_atomically(path, "EXR", [&](const std::string& tmp) {
        const char* err = nullptr;
        const int rc = SaveEXR(img.data.data(), img.width, img.height, img.channels, half ? 1 : 0, tmp.c_str(), &err);
        if (rc != TINYEXR_SUCCESS) {
            std::string msg = err ? err : "unknown error";
            if (err) FreeEXRErrorMessage(err);
            for (char& c : msg)
                if (c == '\n') c = ' ';
            throw Error(strfmt("cannot write EXR '%s': %s", path.c_str(), msg.c_str()));
        }
    });
}

size_t count_non_finite(const Image& img) {
    size_t n = 0;
    for (float v : img.data) n += std::isfinite(v) ? 0 : 1;
    return n;
}

size_t sanitize_non_finite(Image& img, float max_value) {
    size_t n = 0;
    for (float& v : img.data) {
        if (std::isfinite(v)) continue;
        v = (v > 0.0f) ? max_value : 0.0f;
        ++n;
    }
    return n;
}

Image convert_channels(const Image& img, int channels) {
    NBVH_CHECK(channels >= 1 && channels <= 4 && img.channels >= 1 && img.channels <= 4);
    Image out(img.width, img.height, channels);
    for (size_t i = 0; i < img.pixel_count(); ++i) {
        const float* s = img.data.data() + i * size_t(img.channels);
        float* d = out.data.data() + i * size_t(channels);
        for (int c = 0; c < channels; ++c) {
            if (c == 3) d[c] = img.channels == 4 ? s[3] : 1.0f;
            else if (channels == 1) d[c] = img.channels >= 3 ? 0.2126f * s[0] + 0.7152f * s[1] + 0.0722f * s[2] : s[0];
            else d[c] = img.channels >= 3 ? s[c] : s[0];
        }
    }
    return out;
}

} // namespace nbvh
