// Packs a Scene and its SceneAccel into the flat arrays the wavefront shaders read
// (shaders/shared/scene_gpu.h). Pure CPU, so it is unit-tested without a device; GpuSceneBuffers
// (wavefront.h) uploads the result.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/bvh/scene_accel.h"
#include "engine/bvh/wide_bvh.h"
#include "engine/render/environment_sampler.h"
#include "engine/scene/scene.h"
#include "shaders/shared/bvh_node.h"
#include "shaders/shared/scene_gpu.h"

namespace nbvh::render {

struct GpuSceneData {
    std::vector<GpuBvhNode> tlas_nodes;   // leaf refs index `instances`
    std::vector<GpuWideNode> blas_nodes;  // all BLASes (4-wide, to_wide_layout); interior refs offset to this array
    std::vector<GpuInstance> instances;   // TLAS leaf order
    std::vector<GpuTriangle> triangles;   // per mesh in BLAS leaf order, concatenated
    std::vector<GpuVertex> vertices;      // all meshes' vertices, concatenated
    std::vector<GpuMaterial> materials;
    std::vector<GpuTextureInfo> texture_infos;
    std::vector<uint32_t> texels;         // RGBA8 (buffer texture path; a placeholder word otherwise)
    std::vector<GpuLight> lights;         // emissive triangles, then punctual lights, world space
    std::vector<float> light_cdf;         // emissive_light_count + 1 entries, then punctual_light_count + 1
    float light_total_power = 0.0f;       // of the emissive triangles
    uint32_t emissive_light_count = 0;    // GpuFrameParams::light_count (0 when light_total_power is 0)
    uint32_t punctual_light_count = 0;    // GpuFrameParams::punctual_count (lights of positive power)
    EnvironmentTable environment;

    // For mapping GPU results back to the scene (tests, debugging).
    std::vector<uint32_t> instance_to_scene;   // GPU instance -> Scene::instances index
    std::vector<uint32_t> triangle_to_mesh_triangle; // GPU triangle -> original triangle id in its mesh
    float scene_extent = 1.0f;                  // world bounds diagonal (m)
    uint32_t texture_downscales = 0;            // halvings applied to fit the texel budget
    uint32_t outline_shells = 0;                // instances packed as NB_INSTANCE_CAMERA_ONLY
    uint32_t omitted_meshes = 0;                // meshes left out (PackOptions::omit_mesh)
    uint64_t omitted_bytes = 0;                 // their vertices, triangles and BLAS nodes
    uint32_t omitted_unbuilt = 0;               // of them, meshes whose BLAS was never built (bounds only)
};

struct PackOptions {
    // false: no texel upload (the scene fetches no texel, or the texture-array path holds them as images)
    bool textures = true;
    uint64_t texel_budget_bytes = 96ull << 20;  // below lavapipe's 128 MiB per binding (texture_path.h)
    uint64_t environment_budget_bytes = UINT64_MAX; // the environment map is halved until its table fits
    // Per Scene::meshes entry (empty: none): not uploaded. Its vertices, triangles and BLAS nodes are left
    // out, its instances point at an empty BLAS and add no light. For meshes only the model answers for
    // (omitted_neural_meshes). A mesh whose BLAS is bounds-only (build_scene_accel_bounds_only) must be
    // omitted: pack_scene throws otherwise.
    std::vector<bool> omit_mesh;
};

// The meshes a hybrid-only render need not upload: every instance neural, no emissive material.
std::vector<bool> omitted_neural_meshes(const Scene& scene);

// `environment` is the one the render uses (scene's, --env, or the default sky).
GpuSceneData pack_scene(const Scene& scene, const SceneAccel& accel, const Environment& environment,
                        const PackOptions& options = {});

} // namespace nbvh::render
