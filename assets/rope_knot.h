// The detailed asset of the built-in scene: a (2,3) torus knot swept by a twisted, fibrous rope
// profile. Its fine relief (strands, fibre grooves and a bumpy surface at a few millimetres) is the
// kind of geometry the N-BVH replaces: hundreds of thousands of small triangles inside a compact volume.
#pragma once
#include <cstdint>

#include "engine/scene/scene.h"

namespace nbvh::assets {

struct RopeKnotParams {
    uint32_t segments_along = 1200; // samples along the knot curve
    uint32_t segments_around = 160; // samples around the tube
    float scale = 0.22f;            // metres per unit of the canonical knot (the knot spans ~±3.55 units)
    float tube_radius = 0.55f;      // canonical units, before the relief (must stay < 0.8)
    uint32_t strands = 5;           // rope strands around the tube
    uint32_t twists = 48;           // strand turns along the whole loop
};

// Triangles = 2 · segments_along · segments_around (384,000 with the defaults). Closed, watertight
// (seams share vertices), smooth area-weighted normals, uv0 = (along, around) in [0,1).
// The knot lies in the xy plane (z is its thickness), centred at the origin.
Mesh make_rope_knot(const RopeKnotParams& params, uint32_t material);

} // namespace nbvh::assets
