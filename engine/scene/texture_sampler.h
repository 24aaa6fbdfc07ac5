// CPU texture fetch (the trainer's ground truth, neural assets' material constants): bilinear, wrap
// (glTF default sampler), with the KHR_texture_transform of the reference applied. Base-colour texels are sRGB-encoded 8-bit and are
// decoded to linear here, so the albedo target is linear RGB (the official code skips the decode,
// notes §14; we follow glTF).
#pragma once
#include <glm/glm.hpp>

#include "engine/core/image.h"
#include "engine/scene/scene.h"

namespace nbvh {

// Linear RGBA at `uv` (already the UV set the reference names). `srgb` decodes RGB from sRGB.
glm::vec4 sample_texture_bilinear(const Texture& texture, glm::vec2 uv, bool srgb);

// Texture lookup through a TextureRef (applies its transform). Returns `fallback` when the reference
// is empty or points outside `textures`.
glm::vec4 sample_texture_ref(const std::vector<Texture>& textures, const TextureRef& ref, glm::vec2 uv, bool srgb,
                             glm::vec4 fallback);

// srgb_to_linear(): engine/core/image.h (one definition for the whole project).

} // namespace nbvh
