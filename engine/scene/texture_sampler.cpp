#include "engine/scene/texture_sampler.h"

#include <array>
#include <cmath>

namespace nbvh {

namespace {

// 256-entry table: decoding 8-bit sRGB is the hot path of albedo ground truth.
const std::array<float, 256>& srgb_table() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int i = 0; i < 256; ++i) t[size_t(i)] = srgb_to_linear(float(i) / 255.0f);
        return t;
    }();
    return table;
}

// Wrap a texel coordinate into [0, n) (glTF REPEAT).
inline int wrap(int i, int n) {
    const int m = i % n;
    return m < 0 ? m + n : m;
}

} // namespace

glm::vec4 sample_texture_bilinear(const Texture& texture, glm::vec2 uv, bool srgb) {
    const int w = int(texture.width), h = int(texture.height);
    if (w <= 0 || h <= 0 || texture.rgba8.size() < size_t(w) * size_t(h) * 4u) return glm::vec4(1.0f);
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) uv = glm::vec2(0.0f);
    // Keep only the fractional part first so huge UVs do not overflow the int conversion.
    uv -= glm::floor(uv);
    const float x = uv.x * float(w) - 0.5f, y = uv.y * float(h) - 0.5f; // texel centres at +0.5
    const float fx = std::floor(x), fy = std::floor(y);
    const float ax = x - fx, ay = y - fy;
    const int x0 = wrap(int(fx), w), y0 = wrap(int(fy), h);
    const int x1 = wrap(x0 + 1, w), y1 = wrap(y0 + 1, h);
    const auto& table = srgb_table();
    auto texel = [&](int tx, int ty) {
        const uint8_t* p = &texture.rgba8[(size_t(ty) * size_t(w) + size_t(tx)) * 4u];
        if (srgb) return glm::vec4(table[p[0]], table[p[1]], table[p[2]], float(p[3]) / 255.0f);
        return glm::vec4(p[0], p[1], p[2], p[3]) / 255.0f;
    };
    const glm::vec4 top = glm::mix(texel(x0, y0), texel(x1, y0), ax);
    const glm::vec4 bottom = glm::mix(texel(x0, y1), texel(x1, y1), ax);
    return glm::mix(top, bottom, ay);
}

glm::vec4 sample_texture_ref(const std::vector<Texture>& textures, const TextureRef& ref, glm::vec2 uv, bool srgb,
                             glm::vec4 fallback) {
    if (ref.texture < 0 || size_t(ref.texture) >= textures.size()) return fallback;
    const glm::vec3 t = ref.transform * glm::vec3(uv, 1.0f);
    return sample_texture_bilinear(textures[size_t(ref.texture)], glm::vec2(t), srgb);
}

} // namespace nbvh
