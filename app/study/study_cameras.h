// The cameras of a study (issue 11: the scene's or the paper's camera plus two more): the --camera ones
// first, then the scene's camera (auto-framed when it has none), then orbits of the first camera around
// its target until there are `count`. Orbit k (1, 2, ...) turns the eye about the camera's up axis by
// +-60 deg x ceil(k/2) (odd k: left and 10 deg higher; even k: right, 5 deg lower and 25 % closer, so
// one view sees the neural assets larger), keeping target, up and field of view.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "engine/scene/scene.h"

namespace nbvh::app {

std::vector<Camera> study_cameras(const Scene& scene, const std::vector<std::string>& given, uint32_t count,
                                  float aspect);

// The orbit of `base` described above (k >= 1).
Camera orbit_camera(const Camera& base, uint32_t k);

// "ex,ey,ez,tx,ty,tz,fov_deg" of a camera (the --camera form, for result files).
std::string camera_string(const Camera& c);

} // namespace nbvh::app
