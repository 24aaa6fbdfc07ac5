// What the glTF loader implements and how it names the rest (internal to the loader): every extension a
// file uses that we do not implement gets one warning naming it, whatever the number of materials or
// nodes using it; an unsupported extension in `extensionsRequired` is a one-line nbvh::Error; core
// features we ignore (animations, vertex colours, sampler wrap modes) get one line each.
#pragma once
#include <string>
#include <vector>

namespace tinygltf {
class Model;
}

namespace nbvh::gltf {

// Extensions the loader implements, or that need nothing to render as specified (FB_ngon_encoding only
// orders triangles). Implementing one means adding it to the list in gltf_support.cpp.
bool extension_supported(const std::string& name);

// Throws nbvh::Error "<file>: requires extension X (not supported by nbvh)" naming every unsupported
// extension in `required`. tinygltf fills Model::extensionsRequired before it reads any buffer, so
// this also explains a parse that failed on buffers only the extension can decode (meshopt fallbacks).
void check_required_extensions(const std::vector<std::string>& required, const std::string& file);

// Warns once per unsupported extension the file uses (declared in extensionsUsed, or an `extensions`
// object on any glTF object) and once per ignored core feature. Returns the extension names warned
// about, sorted (for tests).
std::vector<std::string> warn_ignored_features(const tinygltf::Model& model, const std::string& file);

} // namespace nbvh::gltf
