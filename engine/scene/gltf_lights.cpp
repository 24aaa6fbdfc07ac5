#include "engine/scene/gltf_lights.h"

#include <algorithm>
#include <cmath>

#include <tiny_gltf.h>

#include "engine/core/error.h"
#include "engine/core/log.h"

namespace nbvh::gltf {
namespace {

constexpr double HALF_PI = 1.57079632679489662;

bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// The "light" index of a node's KHR_lights_punctual object, -1 when absent or not an integer.
int light_index(const tinygltf::Node& node) {
    auto it = node.extensions.find("KHR_lights_punctual");
    if (it == node.extensions.end() || !it->second.IsObject() || !it->second.Has("light")) return -1;
    const tinygltf::Value& v = it->second.Get("light");
    if (!v.IsNumber()) return -2;
    const double d = v.IsInt() ? double(v.Get<int>()) : v.Get<double>();
    return d >= 0.0 && d == std::floor(d) && d < 2.0e9 ? int(d) : -2;
}

} // namespace

std::optional<PunctualLight> node_light(const tinygltf::Model& model, const tinygltf::Node& node,
                                        int node_index, const glm::dmat4& world, const std::string& file) {
    const int index = light_index(node);
    if (index == -1) return std::nullopt;
    const std::string where = strfmt("%s: node %d ('%s')", file.c_str(), node_index, node.name.c_str());
    if (index < 0 || size_t(index) >= model.lights.size()) {
        log_warn("%s: KHR_lights_punctual light index is invalid or out of range (%zu lights); ignored",
                 where.c_str(), model.lights.size());
        return std::nullopt;
    }
    const tinygltf::Light& src = model.lights[size_t(index)];
    PunctualLight l;
    l.name = src.name.empty() ? strfmt("light%d", index) : src.name;
    const std::string what = where + " light '" + l.name + "'";
    if (src.type == "point")
        l.type = LightType::point;
    else if (src.type == "spot")
        l.type = LightType::spot;
    else if (src.type == "directional")
        l.type = LightType::directional;
    else {
        log_warn("%s: unknown type '%s'; ignored", what.c_str(), src.type.c_str());
        return std::nullopt;
    }
    if (src.color.size() == 3) {
        const glm::dvec3 c(src.color[0], src.color[1], src.color[2]);
        if (finite(c) && c.x >= 0.0 && c.y >= 0.0 && c.z >= 0.0 &&
            glm::all(glm::lessThan(c, glm::dvec3(1.0e30))))
            l.color = glm::vec3(c);
        else
            log_warn("%s: colour is not in [0, 1e30)^3; white used", what.c_str());
    } else if (!src.color.empty()) {
        log_warn("%s: colour does not have 3 components; white used", what.c_str());
    }
    if (!std::isfinite(src.intensity) || src.intensity < 0.0 || src.intensity > 1.0e30) {
        log_warn("%s: intensity %g is not a finite non-negative number; ignored", what.c_str(),
                 src.intensity);
        return std::nullopt;
    }
    l.intensity = float(src.intensity);
    if (l.type != LightType::directional && src.range != 0.0) {
        // Spec: range > 0 when defined; 0 is tinygltf's "absent" (infinite).
        if (std::isfinite(src.range) && src.range > 0.0 && src.range < 1.0e30)
            l.range = std::max(float(src.range), 1.0e-30f);
        else
            log_warn("%s: range %g is not a positive number below 1e30; the light has infinite range",
                     what.c_str(), src.range);
    }
    if (l.type == LightType::spot) {
        const double inner = src.spot.innerConeAngle, outer = src.spot.outerConeAngle;
        // Kept in float: the outer cone at least 1e-4 rad, the inner one strictly inside it.
        const float o =
            std::isfinite(outer) ? float(std::clamp(outer, 1.0e-4, HALF_PI)) : float(HALF_PI / 2.0);
        const float i = std::isfinite(inner) ? std::clamp(float(inner), 0.0f, o * 0.999f) : 0.0f;
        if (!(inner >= 0.0 && inner < outer && outer <= HALF_PI))
            log_warn("%s: cone angles inner %g, outer %g outside 0 <= inner < outer <= pi/2; using %g, %g",
                     what.c_str(), inner, outer, double(i), double(o));
        l.inner_cone = i;
        l.outer_cone = o;
    }
    // Position: the node's origin; direction: its -z axis (lights point down -z, the extension spec).
    // Beyond 1e9 m (the loader's world-coordinate limit for geometry) float products overflow.
    const glm::dvec3 p(world[3]);
    const glm::dvec3 d = -glm::dvec3(world[2]);
    const double dl = glm::length(d);
    if (!finite(p) || glm::any(glm::greaterThan(glm::abs(p), glm::dvec3(1.0e9))) || !(dl > 0.0) ||
        !std::isfinite(dl)) {
        log_warn("%s: the node's transform is degenerate, non-finite or beyond 1e9 m; light ignored",
                 what.c_str());
        return std::nullopt;
    }
    l.position = glm::vec3(p);
    l.direction = glm::normalize(glm::vec3(d / dl));
    return l;
}

} // namespace nbvh::gltf
