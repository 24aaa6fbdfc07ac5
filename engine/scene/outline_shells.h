// Inverted-hull outlines: a toon-style outline is a slightly inflated copy of an object with its faces
// turned inwards and a single-sided (usually black) material. A rasterizing glTF viewer culls its back
// faces, so only the rim beyond the object's silhouette shows, and it casts no shadow (viewers have none).
// In a path tracer with back-face culling on every ray the shell's inward front faces still enclose the
// object: every ray leaving the object hits them, the object goes black. Such shells are therefore seen by
// camera rays only (the renderer's NB_INSTANCE_CAMERA_ONLY): the image is the object's, plus the rim.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/scene/scene.h"

namespace nbvh {

// The instances that are outline shells: every triangle single-sided, the surface facing inwards (area-
// weighted normals point to the mesh's centre: score <= -INWARD_SCORE of the ideal -1), and closely
// enclosing another instance that is not itself a shell (its world bounds inside the shell's, grown by 2 %
// of the shell's diagonal, and at least ENCLOSED_FRACTION of the shell's diagonal). Rooms and sky domes
// modelled inside-out fail the last test (their contents are much smaller than they are).
std::vector<bool> find_outline_shells(const Scene& scene);

constexpr float OUTLINE_INWARD_SCORE = 0.5f;
constexpr float OUTLINE_ENCLOSED_FRACTION = 0.7f;

// The mesh's inwardness in [-1, 1] (object space): sum over triangles of dot(area normal, centroid - c) /
// sum of |area normal| |centroid - c|, c the bounds centre. +1 for a convex closed mesh facing out, -1 in.
float facing_score(const Mesh& mesh);

} // namespace nbvh
