// A scene scaled by `scale` about the origin and then moved by `offset` (tests of issue 12 "Any scale,
// anywhere"): every instance transform, the punctual lights (positions and ranges; point and spot
// intensities x scale^2, so that the irradiance at the scaled distances stays the same) and a glTF camera.
// Radiance-based inputs (emissive triangles, environment) do not depend on scale, so a renderer free of
// scale-dependent constants renders the same image.
#pragma once
#include <glm/gtc/matrix_transform.hpp>

#include "engine/scene/scene.h"

namespace nbvh::test {

inline Scene scaled_scene(Scene s, float scale, const glm::vec3& offset) {
    const glm::mat4 m = glm::translate(glm::mat4(1.0f), offset) * glm::scale(glm::mat4(1.0f), glm::vec3(scale));
    for (Instance& inst : s.instances) inst.object_to_world = m * inst.object_to_world;
    for (PunctualLight& l : s.lights) {
        l.position = glm::vec3(m * glm::vec4(l.position, 1.0f));
        l.range *= scale;
        if (l.type != LightType::directional) l.intensity *= scale * scale;
    }
    s.camera.eye = glm::vec3(m * glm::vec4(s.camera.eye, 1.0f));
    s.camera.target = glm::vec3(m * glm::vec4(s.camera.target, 1.0f));
    return s;
}

} // namespace nbvh::test
