// glTF materials and textures -> nbvh::Material / nbvh::Texture (internal to the glTF loader).
#pragma once
#include <map>
#include <string>
#include <vector>

#include "engine/scene/scene.h"

namespace tinygltf {
class Model;
struct Image;
} // namespace tinygltf

namespace nbvh::gltf {

// State of tinygltf's image callback: we decode with stb_image ourselves so that a broken image is a
// warning (the material then goes without that texture), never a failed load, and so that textures can
// be skipped entirely (keep_textures = false: geometry-only loads for the trainer).
// Images that share their bytes (one bufferView or one uri) are decoded once (convert_materials shares
// the texture), and all decoded images together stay under a budget: a small file cannot make the loader
// decode one 8192^2 image many times or hold more than 4 GiB of texels.
inline constexpr uint64_t MAX_DECODED_TEXEL_BYTES = 4ull << 30;
struct ImageDecodeContext {
    bool decode = true;
    int failures = 0;
    uint64_t decoded_bytes = 0;
    std::map<std::pair<const unsigned char*, int>, int> first_with_bytes; // (data, size) -> image index
};

// Matches tinygltf::LoadImageDataFunction. Always returns true; failures leave the image empty with a warning.
bool decode_image(tinygltf::Image* image, int image_index, std::string* err, std::string* warn, int req_width,
                  int req_height, const unsigned char* bytes, int size, void* user_data);

// Fills scene.materials (one per glTF material, then one default material appended last) and
// scene.textures (one per decoded glTF image that a material uses). Returns the default material's index.
uint32_t convert_materials(const tinygltf::Model& model, bool keep_textures, Scene& scene);

// uv' = M * (uv, 1) for KHR_texture_transform (offset, rotation in radians, scale): M = T * R * S with the
// rotation direction of glTF#1563 (see the .cpp).
glm::mat3 texture_transform(glm::vec2 offset, float rotation, glm::vec2 scale);

} // namespace nbvh::gltf
