// The triangle BLAS as the shaders traverse it: the binary SAH BVH (bvh.h) collapsed into 4-wide nodes
// with 8-bit quantized child boxes (shaders/shared/wide_bvh_node.h), and a CPU traversal of that layout
// that runs the shaders' own loop (NB_TRAVERSE_WIDE), for tests.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "engine/bvh/bvh.h"
#include "engine/bvh/mesh_bvh.h"
#include "shaders/shared/wide_bvh_node.h"

namespace nbvh {

// The exact (fp32) boxes of a wide node's children; empty (Aabb{}) for absent children.
using WideChildBounds = std::array<Aabb, NB_WIDE_ARITY>;

// Collapses `bvh` (Ylitie et al. 2017, §3 reduced to 4 children): a wide node starts from a binary
// interior node's two children and replaces the interior child of largest surface area by its two
// children until it has 4 or only leaves. Binary leaves stay leaves (references as in bvh_node.h, into
// `prim_indices` order). Node 0 is the root, nodes are in depth-first order, interior references are
// indices into the returned array (callers concatenating several trees add their offset). A BVH that is
// one leaf gives one node with one child; an empty BVH one node without children (no ray enters it).
// Child boxes are quantized outward against the node's box (see wide_bvh_node.h); `exact`, when given,
// receives the exact boxes per node. Throws nbvh::Error for bounds wider than 1e37 on an axis.
std::vector<GpuWideNode> to_wide_layout(const Bvh& bvh, std::vector<WideChildBounds>* exact = nullptr);

// Closest (any = false) or any hit in [tmin, tmax] of `ray` against `mesh`'s triangles through `nodes`
// = to_wide_layout(mesh.bvh), with NB_TRAVERSE_WIDE (the GLSL loop) and the GLSL leaf test (sheared
// watertight triangles, back faces of single-sided triangles culled as MeshBvh's queries do). `hit` is
// written only when it returns true; hit.triangle is the original mesh triangle id.
bool wide_intersect(const std::vector<GpuWideNode>& nodes, const MeshBvh& mesh, const Ray& ray, float tmin,
                    float tmax, bool any, Hit& hit);

} // namespace nbvh
