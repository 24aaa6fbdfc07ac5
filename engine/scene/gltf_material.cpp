#include "engine/scene/gltf_material.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <stb_image.h>
#include <tiny_gltf.h>

#include "engine/core/error.h"
#include "engine/core/log.h"

namespace nbvh::gltf {
namespace {

// Largest accepted texture edge (texels): larger images are skipped with a warning instead of allocating.
constexpr int MAX_TEXTURE_EDGE = 16384;

float finite_or(double v, float fallback) { return std::isfinite(v) ? float(v) : fallback; }

// A number property of an extension object, or `fallback` when absent / not a number / not finite.
float ext_number(const tinygltf::Value& obj, const char* key, float fallback) {
    if (!obj.IsObject() || !obj.Has(key)) return fallback;
    const tinygltf::Value& v = obj.Get(key);
    return v.IsNumber() ? finite_or(v.GetNumberAsDouble(), fallback) : fallback;
}

glm::vec2 ext_vec2(const tinygltf::Value& obj, const char* key, glm::vec2 fallback) {
    if (!obj.IsObject() || !obj.Has(key)) return fallback;
    const tinygltf::Value& v = obj.Get(key);
    if (!v.IsArray() || v.ArrayLen() != 2 || !v.Get(0).IsNumber() || !v.Get(1).IsNumber()) return fallback;
    return glm::vec2(finite_or(v.Get(0).GetNumberAsDouble(), fallback.x),
                     finite_or(v.Get(1).GetNumberAsDouble(), fallback.y));
}

struct TextureTable {
    const tinygltf::Model& model;
    bool keep;
    Scene& scene;
    std::map<int, int32_t> image_to_texture; // glTF image -> Scene::textures index (-1 = unusable)

    // The first image with the same source (bufferView, else uri) as `image`: decode_image decoded only
    // that one.
    int source_of(int image) const {
        const tinygltf::Image& img = model.images[size_t(image)];
        for (int i = 0; i < image; ++i) {
            const tinygltf::Image& o = model.images[size_t(i)];
            if ((img.bufferView >= 0 && o.bufferView == img.bufferView) || (img.bufferView < 0 && !img.uri.empty() && o.uri == img.uri))
                return i;
        }
        return image;
    }

    // Resolves a textureInfo (glTF texture index, texCoord, extensions) into a TextureRef.
    TextureRef resolve(int texture_index, int tex_coord, const tinygltf::ExtensionMap& extensions, bool srgb,
                       const std::string& what) {
        TextureRef ref;
        if (texture_index < 0 || !keep) return ref;
        if (size_t(texture_index) >= model.textures.size()) {
            log_warn("%s: texture %d does not exist; ignored", what.c_str(), texture_index);
            return ref;
        }
        const int image_index = model.textures[size_t(texture_index)].source;
        if (image_index < 0 || size_t(image_index) >= model.images.size()) {
            log_warn("%s: texture %d has no usable image source; ignored", what.c_str(), texture_index);
            return ref;
        }
        auto it = image_to_texture.find(source_of(image_index));
        if (it == image_to_texture.end()) {
            const tinygltf::Image& img = model.images[size_t(source_of(image_index))];
            int32_t slot = -1;
            const bool ok = img.width > 0 && img.height > 0 && img.component == 4 && img.bits == 8 &&
                            img.image.size() == size_t(img.width) * size_t(img.height) * 4;
            if (ok) {
                Texture t;
                t.name = img.name.empty() ? img.uri : img.name;
                t.width = uint32_t(img.width);
                t.height = uint32_t(img.height);
                t.rgba8 = img.image;
                slot = int32_t(scene.textures.size());
                scene.textures.push_back(std::move(t));
            } else {
                log_warn("%s: image %d ('%s') could not be loaded; the material goes without it", what.c_str(),
                         image_index, img.uri.c_str());
            }
            it = image_to_texture.emplace(source_of(image_index), slot).first;
        }
        ref.texture = it->second;
        if (ref.texture < 0) return ref;
        if (srgb) scene.textures[size_t(ref.texture)].srgb = true;
        ref.uv_set = tex_coord == 1 ? 1u : 0u;
        if (tex_coord > 1) log_warn("%s: TEXCOORD_%d is not supported; using TEXCOORD_0", what.c_str(), tex_coord);
        auto ext = extensions.find("KHR_texture_transform");
        if (ext != extensions.end() && ext->second.IsObject()) {
            const tinygltf::Value& tt = ext->second;
            ref.transform = texture_transform(ext_vec2(tt, "offset", glm::vec2(0.0f)), ext_number(tt, "rotation", 0.0f),
                                              ext_vec2(tt, "scale", glm::vec2(1.0f)));
            if (tt.Has("texCoord") && tt.Get("texCoord").IsNumber())
                ref.uv_set = tt.Get("texCoord").GetNumberAsInt() == 1 ? 1u : 0u;
        }
        return ref;
    }
};

} // namespace

glm::mat3 texture_transform(glm::vec2 offset, float rotation, glm::vec2 scale) {
    // Column-major. The rotation is the transpose of the one in the extension's GLSL listing, which is known
    // to be wrong (KhronosGroup/glTF#1563): glTF UVs have v down, and Blender, Babylon.js, three.js and the
    // extension's own example ("offset [0,1], rotation pi/2, scale 0.5 = lower-left quadrant") all use this.
    const float c = std::cos(rotation), s = std::sin(rotation);
    const glm::mat3 translation(1, 0, 0, 0, 1, 0, offset.x, offset.y, 1);
    const glm::mat3 rot(c, -s, 0, s, c, 0, 0, 0, 1);
    const glm::mat3 scl(scale.x, 0, 0, 0, scale.y, 0, 0, 0, 1);
    return translation * rot * scl;
}

bool decode_image(tinygltf::Image* image, int image_index, std::string* /*err*/, std::string* warn, int, int,
                  const unsigned char* bytes, int size, void* user_data) {
    auto* ctx = static_cast<ImageDecodeContext*>(user_data);
    image->width = image->height = image->component = image->bits = 0;
    image->image.clear();
    if (ctx && !ctx->decode) return true;
    int w = 0, h = 0, n = 0;
    auto fail = [&](const std::string& why) {
        if (ctx) ++ctx->failures;
        if (warn) *warn += strfmt("image %d ('%s'): %s; skipped\n", image_index, image->uri.c_str(), why.c_str());
        return true; // not fatal: the material loses this texture
    };
    if (!bytes || size <= 0) return fail("no data");
    // The same bytes again (images sharing a bufferView): left empty, convert_materials shares the first.
    if (ctx && !ctx->first_with_bytes.emplace(std::make_pair(bytes, size), image_index).second) return true;
    if (!stbi_info_from_memory(bytes, size, &w, &h, &n)) return fail(std::string("cannot decode: ") + stbi_failure_reason());
    if (w <= 0 || h <= 0 || w > MAX_TEXTURE_EDGE || h > MAX_TEXTURE_EDGE)
        return fail(strfmt("size %dx%d outside 1..%d", w, h, MAX_TEXTURE_EDGE));
    const uint64_t texel_bytes = uint64_t(w) * uint64_t(h) * 4u;
    if (ctx && ctx->decoded_bytes + texel_bytes > MAX_DECODED_TEXEL_BYTES)
        return fail(strfmt("decoding it would exceed %llu GiB of texels for the file",
                           (unsigned long long)(MAX_DECODED_TEXEL_BYTES >> 30)));
    if (ctx) ctx->decoded_bytes += texel_bytes;
    unsigned char* pixels = stbi_load_from_memory(bytes, size, &w, &h, &n, 4);
    if (!pixels) return fail(std::string("cannot decode: ") + stbi_failure_reason());
    image->width = w;
    image->height = h;
    image->component = 4;
    image->bits = 8;
    image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    image->image.assign(pixels, pixels + size_t(w) * size_t(h) * 4);
    stbi_image_free(pixels);
    return true;
}

uint32_t convert_materials(const tinygltf::Model& model, bool keep_textures, Scene& scene) {
    TextureTable table{model, keep_textures, scene, {}};
    for (size_t i = 0; i < model.materials.size(); ++i) {
        const tinygltf::Material& src = model.materials[i];
        const std::string what = strfmt("material %zu ('%s')", i, src.name.c_str());
        Material m;
        m.name = src.name.empty() ? strfmt("material%zu", i) : src.name;
        const tinygltf::PbrMetallicRoughness& pbr = src.pbrMetallicRoughness;
        if (pbr.baseColorFactor.size() == 4)
            for (int c = 0; c < 4; ++c) m.base_color[c] = std::clamp(finite_or(pbr.baseColorFactor[c], 1.0f), 0.0f, 1.0f);
        m.base_color_tex = table.resolve(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                                         pbr.baseColorTexture.extensions, true, what + " baseColorTexture");
        m.metallic = std::clamp(finite_or(pbr.metallicFactor, 1.0f), 0.0f, 1.0f);
        m.roughness = std::clamp(finite_or(pbr.roughnessFactor, 1.0f), 0.0f, 1.0f);
        m.metallic_roughness_tex =
            table.resolve(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
                          pbr.metallicRoughnessTexture.extensions, false, what + " metallicRoughnessTexture");
        m.normal_tex = table.resolve(src.normalTexture.index, src.normalTexture.texCoord,
                                     src.normalTexture.extensions, false, what + " normalTexture");
        m.normal_scale = finite_or(src.normalTexture.scale, 1.0f);
        float emissive_strength = 1.0f;
        auto es = src.extensions.find("KHR_materials_emissive_strength");
        if (es != src.extensions.end())
            emissive_strength = std::max(ext_number(es->second, "emissiveStrength", 1.0f), 0.0f);
        if (src.emissiveFactor.size() == 3)
            for (int c = 0; c < 3; ++c)
                m.emissive[c] = std::clamp(finite_or(src.emissiveFactor[c], 0.0f), 0.0f, 1.0f) * emissive_strength;
        m.emissive_tex = table.resolve(src.emissiveTexture.index, src.emissiveTexture.texCoord,
                                       src.emissiveTexture.extensions, true, what + " emissiveTexture");
        if (src.alphaMode == "MASK") m.alpha_mode = AlphaMode::mask;
        else if (src.alphaMode == "BLEND") m.alpha_mode = AlphaMode::blend;
        else if (!src.alphaMode.empty() && src.alphaMode != "OPAQUE")
            log_warn("%s: unknown alphaMode '%s'; treated as OPAQUE", what.c_str(), src.alphaMode.c_str());
        m.alpha_cutoff = std::clamp(finite_or(src.alphaCutoff, 0.5f), 0.0f, 1.0f);
        m.double_sided = src.doubleSided;
        auto tr = src.extensions.find("KHR_materials_transmission");
        if (tr != src.extensions.end())
            m.transmission = std::clamp(ext_number(tr->second, "transmissionFactor", 0.0f), 0.0f, 1.0f);
        scene.materials.push_back(std::move(m));
    }
    // The default material (glTF 2.0 §3.9.6: primitives without a material): appended last.
    Material def;
    def.name = "default";
    def.metallic = 0.0f;
    def.roughness = 0.5f;
    def.base_color = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
    scene.materials.push_back(def);
    return uint32_t(scene.materials.size() - 1);
}

} // namespace nbvh::gltf
