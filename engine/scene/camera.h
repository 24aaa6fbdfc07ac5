// Camera helpers: automatic framing, the --camera option, and the look-at basis the renderer uses.
#pragma once
#include <string>

#include "engine/scene/scene.h"

namespace nbvh {

// Orthonormal camera frame (world space): `forward` points from eye to target; right = forward x up.
struct CameraBasis {
    glm::vec3 right{1.0f, 0.0f, 0.0f};
    glm::vec3 up{0.0f, 1.0f, 0.0f};
    glm::vec3 forward{0.0f, 0.0f, -1.0f};
};

// Frame from eye/target/up; robust when up is parallel to the view direction or eye == target
// (falls back to another up / to looking down -z), never returns NaN for finite input.
CameraBasis look_at(const glm::vec3& eye, const glm::vec3& target, const glm::vec3& up = glm::vec3(0, 1, 0));
CameraBasis camera_basis(const Camera& camera);

// A camera that shows the whole scene (world bounds) from the front-right, slightly above, with the
// bounding sphere filling the smaller of the two fovs. Empty scene: the default camera. Scale-free: the
// eye-target distance is a fixed multiple of the bounding-sphere radius at any size (0.1 mm .. 10 km) and
// distance from the origin; point-like scenes stay finite with eye != target.
Camera auto_frame(const Scene& scene, float aspect);

// "ex,ey,ez,tx,ty,tz,fov_deg" (fov vertical, degrees in (0, 180)); throws nbvh::Error naming the problem
// for a wrong count, a non-number, a non-finite value, eye == target or a bad fov.
Camera parse_camera(const std::string& text);

} // namespace nbvh
