#include "engine/scene/gltf_support.h"

#include <algorithm>
#include <map>
#include <set>

#include <tiny_gltf.h>

#include "engine/core/error.h"
#include "engine/core/log.h"

namespace nbvh::gltf {
namespace {

// Implemented (gltf_material.cpp, gltf_accessor.cpp, gltf_lights.cpp), or nothing to render: FB_ngon_encoding only orders
// a polygon's triangles, the XMP extensions carry metadata.
const char* const SUPPORTED[] = {
    "KHR_texture_transform",   "KHR_materials_emissive_strength", "KHR_materials_transmission",
    "KHR_mesh_quantization", // integer and normalized attributes: gltf_accessor.cpp read_floats
    "KHR_lights_punctual",   // gltf_lights.cpp; rendered by next-event estimation (engine/render)
    "FB_ngon_encoding",        "KHR_xmp_json_ld",                 "KHR_xmp",
};

// What the image loses, for the warning (unknown extensions: just "ignored").
const char* consequence(const std::string& name) {
    static const std::map<std::string, const char*> notes = {
        {"KHR_materials_pbrSpecularGlossiness", "the metallic-roughness fallback values are used"},
        {"KHR_materials_volume", "transmission is thin-walled"},
        {"KHR_materials_ior", "index of refraction 1.5"},
        {"KHR_materials_unlit", "shaded as a lit material"},
        {"KHR_materials_variants", "the default materials are shown"},
        {"KHR_texture_basisu", "textures only in that format are dropped"},
        {"EXT_texture_webp", "textures only in that format are dropped"},
        {"EXT_texture_avif", "textures only in that format are dropped"},
        {"MSFT_texture_dds", "textures only in that format are dropped"},
        {"KHR_draco_mesh_compression", "compressed geometry is not decoded"},
        {"EXT_meshopt_compression", "compressed geometry is not decoded"},
        {"EXT_mesh_gpu_instancing", "one copy of each instanced mesh is rendered"},
        {"KHR_animation_pointer", "the rest pose is rendered"},
    };
    auto it = notes.find(name);
    if (it != notes.end()) return it->second;
    if (name.rfind("KHR_materials_", 0) == 0) return "the material is rendered without that layer";
    return "ignored";
}

void collect(const tinygltf::ExtensionMap& extensions, std::set<std::string>& names) {
    for (const auto& [name, value] : extensions) names.insert(name);
}

// Every extension name on any object of the model (files do not always declare what they use).
std::set<std::string> extensions_in(const tinygltf::Model& m) {
    std::set<std::string> n(m.extensionsUsed.begin(), m.extensionsUsed.end());
    n.insert(m.extensionsRequired.begin(), m.extensionsRequired.end());
    collect(m.extensions, n);
    collect(m.asset.extensions, n);
    for (const auto& x : m.scenes) collect(x.extensions, n);
    for (const auto& x : m.nodes) collect(x.extensions, n);
    for (const auto& x : m.meshes) {
        collect(x.extensions, n);
        for (const auto& p : x.primitives) collect(p.extensions, n);
    }
    for (const auto& x : m.materials) {
        collect(x.extensions, n);
        collect(x.pbrMetallicRoughness.extensions, n);
        collect(x.pbrMetallicRoughness.baseColorTexture.extensions, n);
        collect(x.pbrMetallicRoughness.metallicRoughnessTexture.extensions, n);
        collect(x.normalTexture.extensions, n);
        collect(x.occlusionTexture.extensions, n);
        collect(x.emissiveTexture.extensions, n);
    }
    for (const auto& x : m.textures) collect(x.extensions, n);
    for (const auto& x : m.images) collect(x.extensions, n);
    for (const auto& x : m.samplers) collect(x.extensions, n);
    for (const auto& x : m.accessors) collect(x.extensions, n);
    for (const auto& x : m.bufferViews) collect(x.extensions, n);
    for (const auto& x : m.buffers) collect(x.extensions, n);
    for (const auto& x : m.cameras) collect(x.extensions, n);
    for (const auto& x : m.skins) collect(x.extensions, n);
    for (const auto& x : m.animations) collect(x.extensions, n);
    n.erase("");
    return n;
}

} // namespace

bool extension_supported(const std::string& name) {
    return std::find(std::begin(SUPPORTED), std::end(SUPPORTED), name) != std::end(SUPPORTED);
}

void check_required_extensions(const std::vector<std::string>& required, const std::string& file) {
    std::string missing;
    for (const std::string& r : std::set<std::string>(required.begin(), required.end()))
        if (!extension_supported(r)) missing += (missing.empty() ? "" : ", ") + r;
    if (missing.empty()) return;
    const bool several = missing.find(',') != std::string::npos;
    throw Error(strfmt("%s: requires extension%s %s (not supported by nbvh)", file.c_str(), several ? "s" : "",
                       missing.c_str()));
}

std::vector<std::string> warn_ignored_features(const tinygltf::Model& model, const std::string& file) {
    std::vector<std::string> warned;
    for (const std::string& name : extensions_in(model)) {
        if (extension_supported(name)) continue;
        log_warn("%s: extension %s is not supported: %s", file.c_str(), name.c_str(), consequence(name));
        warned.push_back(name);
    }
    // Core features without an extension name, one line each.
    if (!model.animations.empty())
        log_warn("%s: %zu animation%s ignored (the file's node transforms are rendered)", file.c_str(),
                 model.animations.size(), model.animations.size() == 1 ? "" : "s");
    size_t coloured = 0;
    for (const tinygltf::Mesh& mesh : model.meshes)
        for (const tinygltf::Primitive& p : mesh.primitives) coloured += p.attributes.count("COLOR_0");
    if (coloured)
        log_warn("%s: vertex colours (COLOR_0) of %zu primitive%s ignored (base colour factor and texture only)",
                 file.c_str(), coloured, coloured == 1 ? "" : "s");
    size_t clamped = 0;
    for (const tinygltf::Sampler& s : model.samplers)
        clamped += s.wrapS != TINYGLTF_TEXTURE_WRAP_REPEAT || s.wrapT != TINYGLTF_TEXTURE_WRAP_REPEAT;
    if (clamped)
        log_warn("%s: %zu texture sampler%s ask%s for clamped or mirrored wrapping; textures repeat", file.c_str(),
                 clamped, clamped == 1 ? "" : "s", clamped == 1 ? "s" : "");
    return warned;
}

} // namespace nbvh::gltf
