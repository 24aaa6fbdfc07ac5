// Flat midpoint subdivision: the same surface in 4^L times the triangles (`--subdivide L` of `nbvh render`,
// `train`, `bench` and `converge`). Each triangle (a, b, c) becomes four, through the midpoints of its
// edges; a midpoint is shared by the triangles on both sides of its edge (a watertight mesh stays
// watertight). The new vertices lie on the original triangles, so what a ray hits does not change (up to
// float rounding of the midpoints): only the classical side's cost grows (BVH depth, memory beyond the
// GPU's caches), which is how a dense scan (the paper's Statuette, 642 MB) differs from a modest mesh of
// the same shape. Per-vertex attributes are interpolated at the midpoints (normals and tangent directions
// renormalised, a tangent's handedness taken from the edge's lower-indexed vertex); each new triangle
// keeps its parent's material.
#pragma once
#include <cstdint>

#include "engine/scene/scene.h"

namespace nbvh {

// Upper bounds that `subdivide_scene` enforces (nbvh::Error beyond them, nothing changed).
inline constexpr uint32_t MAX_SUBDIVISION_LEVELS = 4;                   // 256x the triangles
inline constexpr uint64_t MAX_SUBDIVIDED_TRIANGLES = uint64_t(1) << 26; // all meshes together (67M)

// One level on one mesh (the mesh's vertex count must stay below 2^32; checked by subdivide_scene).
Mesh subdivide_mesh(const Mesh& mesh);

// `levels` levels on every mesh of the scene. Throws nbvh::Error (one line) for more than
// MAX_SUBDIVISION_LEVELS levels or a result above MAX_SUBDIVIDED_TRIANGLES triangles, before any work.
void subdivide_scene(Scene& scene, uint32_t levels);

} // namespace nbvh
