#include "engine/scene/camera.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "engine/core/error.h"
#include "engine/core/log.h"

namespace nbvh {

CameraBasis look_at(const glm::vec3& eye, const glm::vec3& target, const glm::vec3& up) {
    CameraBasis b;
    glm::vec3 f = target - eye;
    const float fl = glm::length(f);
    b.forward = (fl > 0.0f && std::isfinite(fl)) ? f / fl : glm::vec3(0.0f, 0.0f, -1.0f);
    // Pick the first usable up: the given one, then +y, then +z (parallel or zero ups are skipped).
    for (const glm::vec3& u : {up, glm::vec3(0, 1, 0), glm::vec3(0, 0, 1)}) {
        const glm::vec3 r = glm::cross(b.forward, u);
        const float rl = glm::length(r);
        if (rl > 1e-6f && std::isfinite(rl)) {
            b.right = r / rl;
            b.up = glm::cross(b.right, b.forward);
            return b;
        }
    }
    return b; // unreachable for a unit forward: +y and +z cannot both be parallel to it
}

CameraBasis camera_basis(const Camera& camera) { return look_at(camera.eye, camera.target, camera.up); }

Camera auto_frame(const Scene& scene, float aspect) {
    Camera cam;
    const Aabb b = scene.world_bounds();
    if (b.empty()) return cam;
    const glm::vec3 centre = b.center();
    float radius = 0.5f * glm::length(b.extent());
    if (!std::isfinite(radius) || !std::isfinite(centre.x + centre.y + centre.z)) return cam;
    // No absolute floor (a 0.1 mm asset must be framed like a 10 km one): only enough float spacing
    // around the centre for eye != target (a point-like scene far from the origin), and a tiny absolute
    // value for a point at the origin. 1e-5 |centre| is ~80 float ulps of the centre's coordinates.
    const float max_abs = std::max({std::fabs(centre.x), std::fabs(centre.y), std::fabs(centre.z)});
    radius = std::max({radius, 1e-5f * max_abs, 1e-20f});
    cam.yfov = 0.6f; // ~34 degrees
    const float safe_aspect = (aspect > 0.0f && std::isfinite(aspect)) ? aspect : 1.0f;
    const float half_x = std::atan(std::tan(0.5f * cam.yfov) * safe_aspect);
    const float half = std::min(0.5f * cam.yfov, half_x);
    const float distance = radius / std::sin(half) * 1.05f;
    const glm::vec3 dir = glm::normalize(glm::vec3(0.55f, 0.45f, 1.0f)); // front-right, above
    cam.target = centre;
    cam.eye = centre + dir * distance;
    cam.up = glm::vec3(0.0f, 1.0f, 0.0f);
    return cam;
}

Camera parse_camera(const std::string& text) {
    std::vector<float> v;
    size_t start = 0;
    while (start <= text.size()) {
        size_t end = text.find(',', start);
        if (end == std::string::npos) end = text.size();
        std::string item = text.substr(start, end - start);
        while (!item.empty() && std::isspace(static_cast<unsigned char>(item.front()))) item.erase(item.begin());
        while (!item.empty() && std::isspace(static_cast<unsigned char>(item.back()))) item.pop_back();
        char* stop = nullptr;
        const float x = item.empty() ? 0.0f : std::strtof(item.c_str(), &stop);
        if (item.empty() || stop != item.c_str() + item.size())
            throw Error(strfmt("--camera: '%s' is not a number (expected ex,ey,ez,tx,ty,tz,fov_deg)", item.c_str()));
        if (!std::isfinite(x)) throw Error(strfmt("--camera: value '%s' is not finite", item.c_str()));
        v.push_back(x);
        start = end + 1;
    }
    if (v.size() != 7)
        throw Error(strfmt("--camera: expected 7 comma-separated values ex,ey,ez,tx,ty,tz,fov_deg, got %zu", v.size()));
    Camera cam;
    cam.eye = glm::vec3(v[0], v[1], v[2]);
    cam.target = glm::vec3(v[3], v[4], v[5]);
    if (cam.eye == cam.target) throw Error("--camera: eye and target are the same point");
    if (!(v[6] > 0.0f && v[6] < 180.0f))
        throw Error(strfmt("--camera: fov %g degrees is outside (0, 180)", double(v[6])));
    cam.yfov = v[6] * 3.14159265358979f / 180.0f;
    cam.up = camera_basis(cam).up; // +y unless looking straight up/down
    return cam;
}

} // namespace nbvh
