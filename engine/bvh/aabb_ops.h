// Numerically safe helpers on Aabb (scene.h): finiteness, surface area without overflow, and the
// padding of degenerate extents that the official N-BVH applies to its base BVH
// (BBOX_REGULARISATION: "nodes with an extent <= 1e-4 on an axis are padded to 1e-4", official
// notes §1). None of them produces NaN or infinite bounds from finite input.
#pragma once
#include <algorithm>
#include <cfloat>
#include <cmath>

#include "engine/scene/scene.h"

namespace nbvh {

// Extent the official code pads flat BVH nodes to (world units, per axis).
inline constexpr float BBOX_REGULARISATION = 1e-4f;

inline bool is_finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
inline bool is_finite(const Aabb& b) { return is_finite(b.lo) && is_finite(b.hi); }
// A box the builder can use: finite and lo <= hi on every axis (a point or flat box is valid).
inline bool is_valid(const Aabb& b) { return is_finite(b) && !b.empty(); }

// Half the surface area, in double so that extents up to 3.4e38 do not overflow; 0 for empty boxes.
inline double half_area(const Aabb& b) {
    if (b.empty()) return 0.0;
    double x = double(b.hi.x) - b.lo.x, y = double(b.hi.y) - b.lo.y, z = double(b.hi.z) - b.lo.z;
    return x * y + y * z + z * x;
}
// Sum of the extents (the SAH measure used when a box is flat on two axes and its area is zero).
inline double half_perimeter(const Aabb& b) {
    if (b.empty()) return 0.0;
    return (double(b.hi.x) - b.lo.x) + (double(b.hi.y) - b.lo.y) + (double(b.hi.z) - b.lo.z);
}

// Union of two boxes (empty boxes are neutral).
inline Aabb merge(const Aabb& a, const Aabb& b) {
    Aabb r = a;
    r.grow(b);
    return r;
}

inline bool contains(const Aabb& outer, const Aabb& inner) {
    if (inner.empty()) return true;
    return outer.lo.x <= inner.lo.x && outer.lo.y <= inner.lo.y && outer.lo.z <= inner.lo.z &&
           outer.hi.x >= inner.hi.x && outer.hi.y >= inner.hi.y && outer.hi.z >= inner.hi.z;
}

// Pads every axis whose extent is below `min_extent` to `min_extent`, centred on the box. At large
// coordinates the padded bounds are at least one float ulp apart on each side, so the result is
// never flat; finite input stays finite (the ends saturate at +-FLT_MAX). Empty or non-finite boxes
// are returned unchanged.
inline Aabb pad_degenerate(const Aabb& b, float min_extent = BBOX_REGULARISATION) {
    if (!is_valid(b) || !(min_extent > 0.0f)) return b;
    Aabb r = b;
    for (int a = 0; a < 3; ++a) {
        if (double(b.hi[a]) - b.lo[a] >= min_extent) continue;
        double c = 0.5 * (double(b.lo[a]) + b.hi[a]);
        float lo = float(c - 0.5 * min_extent), hi = float(c + 0.5 * min_extent);
        lo = std::min(lo, std::nextafter(b.lo[a], -INFINITY));
        hi = std::max(hi, std::nextafter(b.hi[a], INFINITY));
        r.lo[a] = std::max(lo, -FLT_MAX);
        r.hi[a] = std::min(hi, FLT_MAX);
    }
    return r;
}

// Bounds of `b` under an affine object -> world matrix (the 8 corners). Empty stays empty.
inline Aabb transform_bounds(const glm::mat4& m, const Aabb& b) {
    if (b.empty()) return b;
    Aabb r;
    for (int i = 0; i < 8; ++i) {
        glm::vec3 p((i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z);
        r.grow(glm::vec3(m * glm::vec4(p, 1.0f)));
    }
    return r;
}

} // namespace nbvh
