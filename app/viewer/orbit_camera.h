// The viewer's camera controller: an orbit around a target (left drag), pan in the view plane
// (middle or shift+left drag), dolly (wheel) and WASD/QE fly, converted to the renderer's look-at
// Camera. Engine-free apart from the Camera struct, so it is unit-tested without a window.
#pragma once
#include <glm/glm.hpp>

#include "engine/scene/scene.h"

namespace nbvh::viewer {

class OrbitCamera {
public:
    OrbitCamera() = default;
    // Takes eye/target/fov from `camera` (the scene's, or auto_frame's); `home` for reset().
    explicit OrbitCamera(const Camera& camera);

    Camera camera() const;
    void reset() { *this = OrbitCamera(home_); }

    // Mouse deltas in pixels; `viewport_height` in pixels scales pan so the point under the cursor
    // stays under it. Orbit: 0.25 degrees per pixel; pitch is kept inside (-89, 89) degrees.
    void orbit(float dx_pixels, float dy_pixels);
    void pan(float dx_pixels, float dy_pixels, float viewport_height);
    // Wheel notches: each one moves the eye 10 % of the way to the target (never through it).
    void zoom(float notches);
    // Fly: moves eye and target together, `forward`/`right`/`up` in [-1, 1], `seconds` of motion at
    // one orbit distance per second.
    void fly(float forward, float right, float up, float seconds);

    glm::vec3 target() const { return target_; }
    float distance() const { return distance_; }
    float yaw() const { return yaw_; }
    float pitch() const { return pitch_; }

private:
    glm::vec3 direction() const; // unit vector from target to eye

    Camera home_;
    glm::vec3 target_{0.0f};
    glm::vec3 up_{0.0f, 1.0f, 0.0f};
    float distance_ = 3.0f;
    float yaw_ = 0.0f;   // radians about up_
    float pitch_ = 0.0f; // radians above the plane orthogonal to up_
    float yfov_ = 0.8f;
};

} // namespace nbvh::viewer
