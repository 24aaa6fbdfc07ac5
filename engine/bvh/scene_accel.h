// Two-level acceleration structure of a Scene: one MeshBvh (BLAS) per mesh and a TLAS built with
// build_bvh over instance world bounds. CPU closest/any hit in world space. The renderer packs its
// GPU buffers from this: per mesh to_wide_layout(meshes[m].bvh) (wide_bvh.h) + meshes[m].vertices /
// bvh.prim_indices, and to_gpu_layout(tlas) whose leaf refs index tlas.prim_indices (instance ids).
#pragma once
#include <cstdint>
#include <vector>

#include "engine/bvh/mesh_bvh.h"
#include "engine/scene/scene.h"

namespace nbvh {

struct SceneAccel {
    std::vector<MeshBvh> meshes;             // one per Scene::meshes entry
    Bvh tlas;                                // primitive ids = instance indices (Scene::instances)
    std::vector<glm::mat4> object_to_world;  // per instance (copied from the scene)
    std::vector<glm::mat4> world_to_object;  // per instance; zero matrix for skipped instances
    std::vector<Aabb> instance_bounds;       // world bounds per instance; empty = skipped
    std::vector<uint32_t> instance_mesh;     // per instance: index into meshes
    // Instances are skipped (not in the TLAS) when their matrix is singular or non-finite, their
    // mesh index is out of range, or their mesh has no valid triangle.
};

struct SceneHit {
    float t = NB_INF;                  // world-ray parameter (units of |world dir|)
    uint32_t instance = BVH_INVALID;   // index into Scene::instances
    uint32_t triangle = BVH_INVALID;   // original triangle index in the instance's mesh
    float u = 0.0f, v = 0.0f;          // barycentrics (mesh_bvh.h Hit)
};

// Options for the TLAS (instances overlap a lot: small leaves).
BvhBuildOptions default_tlas_options();

SceneAccel build_scene_accel(const Scene& scene, const BvhBuildOptions& blas_options = default_blas_options(),
                             const BvhBuildOptions& tlas_options = default_tlas_options());

// The same, with the meshes flagged in `bounds_only` (one flag per Scene::meshes entry; missing = false)
// given their bounds only (bounds_only_mesh_bvh): the TLAS is the one build_scene_accel builds, but the
// CPU queries throw on a ray that reaches such a mesh and the renderer must leave it out of the upload
// (render/gpu_scene.h PackOptions::omit_mesh). A hybrid `nbvh render` skips the BLAS builds of the meshes
// only the model answers for this way (the 13.9M-triangle dragon's: ~12 s on 2 cores, 4.9 s on 16).
SceneAccel build_scene_accel_bounds_only(const Scene& scene, const std::vector<bool>& bounds_only);

// World-space queries. The ray is transformed into each instance's object space without
// renormalising the direction, so t is the same parameter in world and object space. Back faces of
// single-sided materials are culled (MeshBvh::single_sided), as in the GPU traversal; outline shells
// (outline_shells.h) count as hit, as for the GPU's camera rays and WavefrontRenderer::trace.
bool intersect_closest(const SceneAccel& accel, const Ray& ray, float tmin, float tmax, SceneHit& hit);
bool intersect_any(const SceneAccel& accel, const Ray& ray, float tmin, float tmax);

// Reference: every triangle of every instance transformed to world space (tests).
bool intersect_closest_brute_force(const Scene& scene, const Ray& ray, float tmin, float tmax, SceneHit& hit);

} // namespace nbvh
