#include "engine/scene/environment.h"

#include <algorithm>
#include <cmath>

#include "engine/core/error.h"
#include "engine/core/image.h"
#include "engine/core/log.h"

namespace nbvh {

Environment load_environment(const std::filesystem::path& path) {
    const std::string file = path.string();
    std::string ext = path.extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext != ".hdr" && ext != ".exr")
        throw Error(strfmt("%s: unsupported environment map format '%s' (expected .hdr or .exr)", file.c_str(),
                           ext.c_str()));
    if (!std::filesystem::exists(path)) throw Error(strfmt("cannot open environment map '%s'", file.c_str()));
    const Image img = load_image(file); // throws nbvh::Error on decode failure
    if (img.width <= 0 || img.height <= 0 || img.data.size() < img.pixel_count() * size_t(img.channels))
        throw Error(strfmt("%s: environment map is empty", file.c_str()));
    if (uint32_t(img.width) > MAX_ENVIRONMENT_EDGE || uint32_t(img.height) > MAX_ENVIRONMENT_EDGE)
        throw Error(strfmt("%s: environment map %dx%d exceeds %u texels per edge", file.c_str(), img.width,
                           img.height, MAX_ENVIRONMENT_EDGE));
    if (img.width != 2 * img.height)
        log_warn("%s: environment map is %dx%d, not 2:1 equirectangular; it will be stretched", file.c_str(),
                 img.width, img.height);
    Environment env;
    env.width = uint32_t(img.width);
    env.height = uint32_t(img.height);
    env.rgb.resize(img.pixel_count() * 3);
    size_t repaired = 0;
    const int ch = img.channels;
    for (size_t p = 0; p < img.pixel_count(); ++p)
        for (int c = 0; c < 3; ++c) {
            float v = img.data[p * ch + size_t(std::min(c, ch - 1))];
            if (!std::isfinite(v) || v < 0.0f) {
                v = 0.0f;
                ++repaired;
            }
            env.rgb[p * 3 + c] = v;
        }
    if (repaired)
        log_warn("%s: %zu non-finite or negative environment texel values set to 0", file.c_str(), repaired);
    return env;
}

Environment default_sky() {
    constexpr uint32_t W = 256, H = 128;
    constexpr float PI = 3.14159265358979f;
    Environment env;
    env.width = W;
    env.height = H;
    env.rgb.resize(size_t(W) * H * 3);
    const glm::vec3 zenith(0.25f, 0.45f, 0.9f), horizon(0.85f, 0.9f, 1.0f), ground(0.3f, 0.27f, 0.24f);
    const glm::vec3 sun_dir = glm::normalize(glm::vec3(0.4f, 0.7f, 0.3f));
    const glm::vec3 sun_colour(12.0f, 11.0f, 9.5f);
    for (uint32_t y = 0; y < H; ++y) {
        const float theta = (float(y) + 0.5f) / float(H) * PI; // polar angle from +y
        for (uint32_t x = 0; x < W; ++x) {
            // Inverse of the mapping in environment.h: u = 0.5 + atan2(d.x, -d.z) / (2 pi).
            const float phi = ((float(x) + 0.5f) / float(W) - 0.5f) * 2.0f * PI;
            const glm::vec3 d(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
            glm::vec3 c;
            if (d.y >= 0.0f) {
                const float t = std::pow(d.y, 0.5f);
                c = glm::mix(horizon, zenith, t);
            } else {
                c = glm::mix(horizon * 0.6f, ground, std::min(1.0f, -d.y * 4.0f));
            }
            // Soft sun lobe: a bright cosine power, wide enough (~5 deg) to be found by uniform sampling too.
            const float cos_sun = std::max(0.0f, glm::dot(d, sun_dir));
            c += sun_colour * std::pow(cos_sun, 400.0f) + glm::vec3(0.3f, 0.25f, 0.15f) * std::pow(cos_sun, 8.0f);
            float* out = &env.rgb[(size_t(y) * W + x) * 3];
            out[0] = c.x;
            out[1] = c.y;
            out[2] = c.z;
        }
    }
    return env;
}

Environment constant_environment(const glm::vec3& radiance) {
    Environment env;
    env.constant = glm::max(radiance, glm::vec3(0.0f));
    return env;
}

} // namespace nbvh
