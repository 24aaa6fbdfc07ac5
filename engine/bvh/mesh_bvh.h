// Per-mesh triangle BVH (BLAS) with triangle vertices reordered into leaf order, and its CPU
// closest-hit / any-hit queries (used by tests, by the renderer's GPU-vs-CPU check and by the CPU
// trainer for ground truth). The renderer uploads to_gpu_layout(bvh) plus `vertices` (or its own
// attribute arrays reordered by bvh.prim_indices).
#pragma once
#include <cstdint>
#include <functional>
#include <vector>

#include "engine/bvh/bvh.h"
#include "engine/bvh/traverse.h"
#include "engine/scene/scene.h"

namespace nbvh {

struct MeshBvh {
    Bvh bvh; // primitive ids are triangle indices of the source Mesh
    // 3 vertices per triangle, in bvh.prim_indices order: triangle k of the leaf order has vertices
    // vertices[3k..3k+2] and original id bvh.prim_indices[k]. Triangles the builder skipped
    // (non-finite vertices, out-of-range indices) are not present.
    std::vector<glm::vec3> vertices;
    // Per triangle in leaf order: 1 = single-sided material, its back faces are culled by the queries below
    // (glTF doubleSided false; the GPU traversal does the same). Empty: nothing is culled (build_mesh_bvh
    // leaves it empty; build_scene_accel fills it from the scene's materials).
    std::vector<uint8_t> single_sided;
    // Set by bounds_only_mesh_bvh: no tree and no vertices, only `only_bounds`, the box of the valid
    // triangles (the root box build_mesh_bvh gives, bit for bit). The CPU queries below throw on it.
    bool bounds_only = false;
    Aabb only_bounds;
    uint32_t triangle_count() const { return uint32_t(bvh.prim_indices.size()); }  // 0 when bounds_only
    bool empty() const { return bounds_only ? only_bounds.empty() : bvh.empty(); } // no valid triangle
    Aabb bounds() const { return bounds_only ? only_bounds : bvh.empty() ? Aabb{} : bvh.nodes[0].bounds; }
};

struct Hit {
    float t = NB_INF;          // ray parameter (units of |dir|)
    uint32_t triangle = BVH_INVALID; // index in the ORIGINAL mesh triangle order
    float u = 0.0f, v = 0.0f;  // barycentrics: p = (1-u-v) v0 + u v1 + v v2
};

// Default options for triangle BLAS.
BvhBuildOptions default_blas_options();

MeshBvh build_mesh_bvh(const Mesh& mesh, const BvhBuildOptions& options = default_blas_options());

// The bounds of `mesh` as build_mesh_bvh's root gives them, without building the tree (one pass over the
// triangles): for a mesh nothing on the CPU traces and nothing uploads (a hybrid render's neural-only
// meshes, render/gpu_scene.h omitted_neural_meshes), whose instances only need their world bounds.
MeshBvh bounds_only_mesh_bvh(const Mesh& mesh);

// Which candidate hits count (alpha-tested surfaces): original triangle index, ray parameter and
// barycentrics. A filter that accepts nothing visits every crossing of [tmin, tmax].
using HitFilter = std::function<bool(uint32_t triangle, float t, float u, float v)>;

// Closest hit with t in [tmin, tmax]; `hit` is written only when it returns true. With `accept`, only
// the hits it accepts. Both queries throw nbvh::Error on a bounds-only MeshBvh.
bool intersect_closest(const MeshBvh& mesh, const Ray& ray, float tmin, float tmax, Hit& hit,
                       const HitFilter* accept = nullptr);
// Any hit with t in [tmin, tmax] (shadow rays).
bool intersect_any(const MeshBvh& mesh, const Ray& ray, float tmin, float tmax);

// Reference: tests every triangle of `mesh` (same intersect.h math). For tests and debugging. With
// `materials`, back faces of single-sided ones are culled as in the BVH queries.
bool intersect_closest_brute_force(const Mesh& mesh, const Ray& ray, float tmin, float tmax, Hit& hit,
                                   const std::vector<Material>* materials = nullptr);

// 1 per triangle of `mesh` in `bvh` leaf order when its material (index into `materials`) is single-sided;
// empty when every material is double-sided (MeshBvh::single_sided).
std::vector<uint8_t> single_sided_flags(const Mesh& mesh, const MeshBvh& bvh, const std::vector<Material>& materials);

} // namespace nbvh
