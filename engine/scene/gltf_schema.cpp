#include "engine/scene/gltf_schema.h"

#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include <nlohmann/json.hpp>

#include "engine/core/error.h"
#include "engine/core/log.h"

namespace nbvh::gltf {
namespace {

using json = nlohmann::json;

// The JSON text of a .gltf, or of a .glb's first chunk ("" when the container is unreadable: tinygltf has
// already accepted it, so this only happens for exotic layouts, and the check is then skipped).
std::string json_text(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0) {
        if (bytes.size() < 20) return "";
        uint32_t length = 0;
        std::memcpy(&length, bytes.data() + 12, 4);
        if (std::memcmp(bytes.data() + 16, "JSON", 4) != 0 || length > bytes.size() - 20) return "";
        return std::string(bytes.data() + 20, length);
    }
    return std::string(bytes.begin(), bytes.end());
}

bool is_index(const json& v) { return v.is_number_integer() || v.is_number_unsigned(); }

bool number_array(const json& v, size_t n) {
    if (!v.is_array() || v.size() != n) return false;
    for (const json& x : v)
        if (!x.is_number()) return false;
    return true;
}

struct Checker {
    std::string file;

    [[noreturn]] void fail(const std::string& where, const std::string& what) const {
        throw Error(strfmt("%s: %s: %s", file.c_str(), where.c_str(), what.c_str()));
    }
    void warn(const std::string& where, const std::string& what) const {
        log_warn("%s: %s: %s; ignored", file.c_str(), where.c_str(), what.c_str());
    }

    void texture_info(const json& m, const char* key, const char* extra_number, const std::string& where) const {
        if (!m.contains(key)) return;
        const json& t = m[key];
        const std::string w = where + "." + key;
        if (!t.is_object()) return warn(w, "is not an object");
        if (!t.contains("index") || !is_index(t["index"])) warn(w, "has no integer 'index'");
        if (t.contains("texCoord") && !is_index(t["texCoord"])) warn(w + ".texCoord", "is not an integer");
        if (extra_number && t.contains(extra_number) && !t[extra_number].is_number())
            warn(w + "." + extra_number, "is not a number");
    }

    void material(const json& m, const std::string& where) const {
        if (!m.is_object()) return warn(where, "is not an object");
        if (m.contains("pbrMetallicRoughness")) {
            const json& p = m["pbrMetallicRoughness"];
            const std::string w = where + ".pbrMetallicRoughness";
            if (!p.is_object()) {
                warn(w, "is not an object");
            } else {
                if (p.contains("baseColorFactor") && !number_array(p["baseColorFactor"], 4))
                    warn(w + ".baseColorFactor", "is not an array of 4 numbers");
                for (const char* k : {"metallicFactor", "roughnessFactor"})
                    if (p.contains(k) && !p[k].is_number()) warn(w + "." + k, "is not a number");
                texture_info(p, "baseColorTexture", nullptr, w);
                texture_info(p, "metallicRoughnessTexture", nullptr, w);
            }
        }
        texture_info(m, "normalTexture", "scale", where);
        texture_info(m, "occlusionTexture", "strength", where);
        texture_info(m, "emissiveTexture", nullptr, where);
        if (m.contains("emissiveFactor") && !number_array(m["emissiveFactor"], 3))
            warn(where + ".emissiveFactor", "is not an array of 3 numbers");
        if (m.contains("alphaCutoff") && !m["alphaCutoff"].is_number()) warn(where + ".alphaCutoff", "is not a number");
        if (m.contains("alphaMode") && !m["alphaMode"].is_string()) warn(where + ".alphaMode", "is not a string");
        if (m.contains("doubleSided") && !m["doubleSided"].is_boolean()) warn(where + ".doubleSided", "is not a boolean");
    }

    void mesh(const json& m, const std::string& where) const {
        if (!m.is_object()) fail(where, "is not an object");
        if (!m.contains("primitives") || !m["primitives"].is_array() || m["primitives"].empty())
            fail(where, "'primitives' must be a non-empty array");
        size_t j = 0;
        for (const json& p : m["primitives"]) {
            const std::string w = where + strfmt(".primitives[%zu]", j++);
            if (!p.is_object()) fail(w, "is not an object");
            if (!p.contains("attributes") || !p["attributes"].is_object()) fail(w, "'attributes' must be an object");
            for (const auto& [name, value] : p["attributes"].items())
                if (!is_index(value)) fail(w + ".attributes." + name, "is not an accessor index");
            for (const char* k : {"indices", "material", "mode"})
                if (p.contains(k) && !is_index(p[k])) fail(w + "." + k, "is not an integer");
        }
    }

    void node(const json& n, const std::string& where) const {
        if (!n.is_object()) fail(where, "is not an object");
        if (n.contains("children")) {
            if (!n["children"].is_array()) fail(where + ".children", "is not an array");
            for (const json& c : n["children"])
                if (!is_index(c)) fail(where + ".children", "contains a non-integer");
        }
        for (const char* k : {"mesh", "camera"})
            if (n.contains(k) && !is_index(n[k])) fail(where + "." + k, "is not an integer");
        const std::pair<const char*, size_t> arrays[] = {{"matrix", 16}, {"translation", 3}, {"rotation", 4}, {"scale", 3}};
        for (const auto& [k, len] : arrays)
            if (n.contains(k) && !number_array(n[k], len)) fail(where + "." + k, strfmt("is not an array of %zu numbers", len));
    }
};

} // namespace

void check_schema(const std::filesystem::path& path) {
    const std::string text = json_text(path);
    if (text.empty()) return;
    const json doc = json::parse(text, nullptr, false);
    if (doc.is_discarded() || !doc.is_object()) return; // tinygltf parsed it; nothing more to add
    const Checker c{path.string()};
    auto each = [&](const char* key, auto&& check) {
        if (!doc.contains(key)) return;
        if (!doc[key].is_array()) c.fail(key, "is not an array");
        size_t i = 0;
        for (const json& item : doc[key]) check(item, strfmt("%s[%zu]", key, i++));
    };
    each("meshes", [&](const json& m, const std::string& w) { c.mesh(m, w); });
    each("nodes", [&](const json& n, const std::string& w) { c.node(n, w); });
    each("materials", [&](const json& m, const std::string& w) { c.material(m, w); });
}

} // namespace nbvh::gltf
