// How the scene's textures reach the shaders: two implementations of one lookup API
// (shaders/lib/textures.glsl: nb_sample_texture), chosen when a renderer is created.
//   buffer: every texture packed into one RGBA8 storage buffer (shader bilinear filtering). Any Vulkan
//           1.2 device, lavapipe included; the buffer is capped (texel_budget_bytes: 96 MiB on lavapipe,
//           1 GiB on NVIDIA), so the largest textures are halved until the scene fits.
//   array:  every glTF image its own VkImage in one `sampler2D[]` binding, indexed nonuniformEXT
//           (descriptor indexing, core in Vulkan 1.2 but optional: Debian 12's lavapipe lacks it); the
//           passes are the NB_TEXTURE_ARRAY variants of shaders/CMakeLists.txt. No cap but the device's
//           descriptor and image limits (a clear error beyond them).
// Both filter the same way: bilinear on the raw 8-bit values, REPEAT wrap, one level (no mip maps),
// texel centres at half-integers, v = 0 the top row; sRGB decode after filtering in the shader.
// Everything here is pure (tested without a device); texture_array.h holds the images.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "engine/scene/scene.h"
#include "engine/vk/context.h"
#include "shaders/shared/neural_gpu.h"

namespace nbvh::render {

enum class TexturePathRequest { automatic, buffer, array }; // --texture-path auto|buffer|array
TexturePathRequest parse_texture_path(std::string_view text); // throws nbvh::Error on anything else

enum class TexturePath { none, buffer, array }; // none: the scene fetches no texel
const char* texture_path_name(TexturePath path);

// What the choice depends on (a vk::DeviceFeatures subset, so the choice is testable without a device).
struct TextureCaps {
    bool runtime_descriptor_array = false;       // runtimeDescriptorArray
    bool sampled_image_array_nonuniform = false; // shaderSampledImageArrayNonUniformIndexing
    uint32_t max_sampled_images = 0;             // combined image samplers per pipeline (all limits)
    uint32_t max_per_stage_resources = 0;
    uint32_t max_image_dimension_2d = 0;
    uint32_t max_memory_allocations = 0;         // one per image
    uint64_t max_storage_buffer_range = 0;       // the buffer path's cap follows it
};
TextureCaps texture_caps(const vk::DeviceFeatures& features);

// Why the array path cannot run on a device with `caps` (missing features), "" when it can.
std::string texture_array_unavailable(const TextureCaps& caps);

// automatic: the array path where the device has the features, else the buffer path; buffer/array as
// requested (array on a device without the features: nbvh::Error naming them). `scene_textures`: the
// scene fetches texels at all (SceneFeatures::textures), else none.
TexturePath choose_texture_path(const TextureCaps& caps, bool scene_textures, TexturePathRequest request);

// The texel buffer's cap: 3/4 of the storage-buffer range, clamped to [96 MiB, 1 GiB].
uint64_t texel_budget_bytes(uint64_t max_storage_buffer_range);

// The buffer path's sizes: the largest texture (by texel count, first on ties) is halved
// (max(1, w / 2) x max(1, h / 2)) until the RGBA8 total fits `budget`; halvings per texture.
// Invalid textures (no texels) count as 1x1. pack_scene applies exactly these halvings.
struct TexelBufferPlan {
    std::vector<uint32_t> halvings; // per texture
    uint32_t total_halvings = 0;
    uint64_t bytes = 0;             // RGBA8 bytes of the packed buffer
};
TexelBufferPlan plan_texel_buffer(const std::vector<Texture>& textures, uint64_t budget);

// A texture with texels for its size; both paths upload an invalid one as 1x1 white.
bool texture_valid(const Texture& t);

// Device resources of the array path: images, descriptors and allocations. Throws nbvh::Error (one
// line, naming the limit) when `textures` exceed them. `other_bindings`: storage buffers beside it.
void check_texture_array_limits(const TextureCaps& caps, const std::vector<Texture>& textures,
                                uint32_t other_bindings);

// What a render's textures are (--explain, --stats): the path, the number of textures and their bytes
// on the GPU (buffer: the packed texels after halvings; array: uncompressed RGBA8 texels, which the
// renderer replaces with the images' allocation sizes once they exist).
struct TexturePlan {
    TexturePath path = TexturePath::none;
    uint32_t textures = 0;
    uint64_t bytes = 0;
    uint32_t halvings = 0;        // buffer path
    uint64_t budget = 0;          // buffer path
    std::string why;              // how the path was chosen
};
// Storage buffers beside the texture binding in the renderer's set 0 (every binding but NB_BIND_TEXELS).
inline constexpr uint32_t RENDERER_BUFFER_BINDINGS = NB_NEURAL_BINDING_END - 1;

// Chooses and sizes the path; throws what the renderer would (unavailable path, array limits).
TexturePlan plan_textures(const TextureCaps& caps, const Scene& scene, bool scene_textures,
                          TexturePathRequest request, uint32_t other_bindings = RENDERER_BUFFER_BINDINGS);
std::string describe(const TexturePlan& plan); // one line, e.g. "array: 33 images, 412.0 MiB (...)"

} // namespace nbvh::render
