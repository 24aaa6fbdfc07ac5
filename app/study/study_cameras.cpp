#include "app/study/study_cameras.h"

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/core/log.h"
#include "engine/scene/camera.h"

namespace nbvh::app {

Camera orbit_camera(const Camera& base, uint32_t k) {
    const CameraBasis b = camera_basis(base);
    const bool odd = (k % 2) == 1;
    const float yaw = glm::radians(60.0f * float((k + 1) / 2)) * (odd ? 1.0f : -1.0f);
    const float pitch = glm::radians(odd ? 10.0f : -5.0f);
    const float scale = odd ? 1.0f : 0.75f;
    const glm::vec3 offset = base.eye - base.target;
    glm::vec3 o = glm::vec3(glm::rotate(glm::mat4(1.0f), yaw, b.up) * glm::vec4(offset, 0.0f));
    // Pitch about the new right axis, unless that would turn the view past the up axis.
    const glm::vec3 right = glm::normalize(glm::cross(-o, b.up));
    const glm::vec3 pitched = glm::vec3(glm::rotate(glm::mat4(1.0f), pitch, right) * glm::vec4(o, 0.0f));
    if (std::fabs(glm::dot(glm::normalize(pitched), b.up)) < 0.95f) o = pitched;
    Camera c = base;
    c.eye = base.target + o * scale;
    return c;
}

std::vector<Camera> study_cameras(const Scene& scene, const std::vector<std::string>& given, uint32_t count,
                                  float aspect) {
    std::vector<Camera> cams;
    for (const std::string& s : given) cams.push_back(parse_camera(s));
    if (cams.empty()) cams.push_back(scene.has_camera ? scene.camera : auto_frame(scene, aspect));
    const Camera base = cams.front();
    for (uint32_t k = 1; cams.size() < count; ++k) cams.push_back(orbit_camera(base, k));
    return cams;
}

std::string camera_string(const Camera& c) {
    return strfmt("%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g", c.eye.x, c.eye.y, c.eye.z, c.target.x, c.target.y,
                  c.target.z, double(glm::degrees(c.yfov)));
}

} // namespace nbvh::app
