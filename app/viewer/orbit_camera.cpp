#include "app/viewer/orbit_camera.h"

#include <algorithm>
#include <cmath>

namespace nbvh::viewer {

namespace {
constexpr float kPitchLimit = 1.5533f;         // 89 degrees, radians
constexpr float kRadiansPerPixel = 0.00436332f; // 0.25 degrees
constexpr float kMinDistance = 1.0e-4f;

// World frame with y = up_: the renderer's scenes are y-up (glTF), so up_ is (0,1,0) unless the
// camera says otherwise; yaw is measured in the x/z plane from +z.
glm::vec3 safe_normalize(const glm::vec3& v, const glm::vec3& fallback) {
    const float len = glm::length(v);
    return len > 1.0e-20f && std::isfinite(len) ? v / len : fallback;
}
} // namespace

OrbitCamera::OrbitCamera(const Camera& camera) : home_(camera) {
    target_ = camera.target;
    up_ = glm::vec3(0.0f, 1.0f, 0.0f);
    yfov_ = camera.yfov;
    const glm::vec3 offset = camera.eye - camera.target;
    distance_ = std::max(glm::length(offset), kMinDistance);
    const glm::vec3 d = safe_normalize(offset, glm::vec3(0.0f, 0.0f, 1.0f));
    pitch_ = std::clamp(std::asin(std::clamp(d.y, -1.0f, 1.0f)), -kPitchLimit, kPitchLimit);
    yaw_ = std::atan2(d.x, d.z);
}

glm::vec3 OrbitCamera::direction() const {
    const float c = std::cos(pitch_);
    return {c * std::sin(yaw_), std::sin(pitch_), c * std::cos(yaw_)};
}

Camera OrbitCamera::camera() const {
    Camera c;
    c.target = target_;
    c.eye = target_ + distance_ * direction();
    c.up = up_;
    c.yfov = yfov_;
    return c;
}

void OrbitCamera::orbit(float dx, float dy) {
    yaw_ -= dx * kRadiansPerPixel;
    pitch_ = std::clamp(pitch_ + dy * kRadiansPerPixel, -kPitchLimit, kPitchLimit);
    // Keep yaw in (-pi, pi] so long drags do not lose float precision.
    yaw_ = std::remainder(yaw_, 6.28318531f);
}

void OrbitCamera::pan(float dx, float dy, float viewport_height) {
    const glm::vec3 fwd = -direction();
    const glm::vec3 right = safe_normalize(glm::cross(fwd, up_), glm::vec3(1.0f, 0.0f, 0.0f));
    const glm::vec3 up = glm::cross(right, fwd);
    // World size of one pixel at the target's depth.
    const float pixel = 2.0f * distance_ * std::tan(0.5f * yfov_) / std::max(viewport_height, 1.0f);
    target_ += (-dx * right + dy * up) * pixel;
}

void OrbitCamera::zoom(float notches) {
    distance_ = std::max(distance_ * std::pow(0.9f, notches), kMinDistance);
}

void OrbitCamera::fly(float forward, float right, float up, float seconds) {
    const glm::vec3 fwd = -direction();
    const glm::vec3 r = safe_normalize(glm::cross(fwd, up_), glm::vec3(1.0f, 0.0f, 0.0f));
    const glm::vec3 move = (forward * fwd + right * r + up * up_) * (distance_ * seconds);
    target_ += move;
}

} // namespace nbvh::viewer
