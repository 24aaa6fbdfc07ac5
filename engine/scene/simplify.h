// Mesh simplification with meshoptimizer (Debian libmeshoptimizer-dev): the baseline that N-BVH is
// compared with at equal memory (paper §5, "decimation"; issue 11). Each material's triangles are
// simplified on their own, so every triangle keeps its material.
#pragma once
#include <cstdint>

#include "engine/scene/scene.h"

namespace nbvh {

struct SimplifyStats {
    uint32_t source_triangles = 0, triangles = 0;
    bool sloppy = false; // some group needed meshopt_simplifySloppy (edge collapse stopped above the target)
};

// `mesh` with about `target_triangles` triangles (at least 1 per material group that had any): edge
// collapse (meshopt_simplify, error unbounded) first; a group whose collapse stops more than 2 % above its
// share of the target (topology, attribute seams) is redone with meshopt_simplifySloppy (vertex
// clustering). Unused vertices are dropped; names, normals, UVs and tangents of the kept vertices stay.
// target_triangles >= the mesh's count returns it unchanged.
Mesh simplify_mesh(const Mesh& mesh, uint32_t target_triangles, SimplifyStats* stats = nullptr);

} // namespace nbvh
