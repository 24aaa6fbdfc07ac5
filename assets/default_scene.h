// The built-in default scene: made entirely by our own code (no files), deterministic, fast (< 1 s).
//   - "neural_rope_knot": a (2,3) torus knot swept by a twisted, fibrous rope (384k triangles of fine
//     relief), flagged `neural` — the asset an N-BVH replaces;
//   - a stone pedestal, a chrome sphere, a blue box, a checkered ground (procedural rgba8 texture);
//   - "lamp_sphere": a small warm emissive sphere;
//   - the procedural default sky (nbvh::default_sky()) as environment light, and a framing camera.
// Units: metres, +y up; the camera looks towards −z.
#pragma once
#include "engine/scene/scene.h"

namespace nbvh::assets {

Scene make_default_scene();

// Name shown for the scene (Scene::source of the default scene).
inline constexpr const char* DEFAULT_SCENE_NAME = "builtin:default";

} // namespace nbvh::assets
