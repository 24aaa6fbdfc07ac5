// The texture-array path's device side (texture_path.h): one RGBA8 UNORM VkImage per glTF texture (full
// size, one level; an invalid texture becomes 1x1 white as in the texel buffer) and one sampler, bound as
// the `sampler2D texture_images[]` array of binding NB_BIND_TEXELS (read with texelFetch: the shader
// filters, lib/textures.glsl).
#pragma once
#include <cstdint>
#include <vector>

#include "engine/scene/scene.h"
#include "engine/vk/image.h"
#include "engine/vk/pipeline.h"

namespace nbvh::render {

class TextureArray {
public:
    TextureArray() = default;
    // Uploads every texture (blocking). Limits are the caller's (check_texture_array_limits).
    TextureArray(const vk::Context& ctx, const std::vector<Texture>& textures);

    // Array size of the binding (at least 1: a scene without textures binds one white texel).
    uint32_t size() const { return uint32_t(images_.size()); }
    uint64_t bytes() const { return bytes_; } // device memory of the images (their allocations)
    // Writes every element of `binding` (declared combined_image_sampler with count size()).
    void bind(vk::DescriptorSet& set, uint32_t binding) const;

private:
    std::vector<vk::Image> images_;
    vk::Sampler sampler_;
    uint64_t bytes_ = 0;
};

} // namespace nbvh::render
