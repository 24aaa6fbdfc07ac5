// Small scenes built in code for the renderer tests.
#pragma once
#include "engine/scene/scene.h"

namespace nbvh::test {

// A unit quad in the z = 0 plane facing +z (two triangles), one grey material, one instance.
Scene make_quad_scene();

} // namespace nbvh::test
