#include "engine/render/texture_array.h"

#include <algorithm>

#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/render/texture_path.h"

namespace nbvh::render {

TextureArray::TextureArray(const vk::Context& ctx, const std::vector<Texture>& textures) {
    // Raw 8-bit values (UNORM, not SRGB): the shader reads four texels with texelFetch and filters them
    // with the buffer path's footprint and weights (lib/textures.glsl), then decodes sRGB (material.glsl).
    // The sampler only completes the combined image sampler; its filter is not used.
    static const uint8_t white[4] = {255, 255, 255, 255};
    const size_t n = std::max<size_t>(textures.size(), 1);
    images_.reserve(n);
    for (size_t i = 0; i < n; ++i) {
        const bool valid = i < textures.size() && texture_valid(textures[i]);
        const uint32_t w = valid ? textures[i].width : 1, h = valid ? textures[i].height : 1;
        const std::string name = i < textures.size() ? strfmt("texture %zu '%s'", i, textures[i].name.c_str())
                                                     : std::string("texture placeholder");
        vk::Image image(ctx, w, h, vk::ImageFormat::rgba8, vk::image_sampled, name);
        image.upload(valid ? textures[i].rgba8.data() : white, size_t(w) * h * 4);
        bytes_ += image.memory_bytes();
        images_.push_back(std::move(image));
    }
    sampler_ = vk::Sampler(ctx, vk::SamplerDesc{true, true});
    log_info("render: %zu textures as images (texture-array path), %.1f MiB", n, double(bytes_) / double(1u << 20));
}

void TextureArray::bind(vk::DescriptorSet& set, uint32_t binding) const {
    for (uint32_t i = 0; i < size(); ++i) set.bind(binding, images_[i], sampler_, i);
}

} // namespace nbvh::render
