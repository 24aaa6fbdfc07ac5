// The scene's feature set: which effects the renderer must simulate (ARCHITECTURE.md "Simulate only
// the effects a scene calls for"). It decides the specialization constants of every pass and which
// passes run at all (no shadow pass without anything to sample, no texture fetch without textures).
#pragma once
#include <string>
#include <vector>

#include "engine/scene/scene.h"
#include "engine/vk/pipeline.h"

namespace nbvh::render {

struct SceneFeatures {
    bool textures = false;      // some material references a texture that exists
    bool normal_maps = false;   // some material has a normal texture
    bool emission = false;      // emissive triangles (-> emissive next-event estimation)
    bool environment = false;   // an environment (map or constant) lights the scene (-> env NEE)
    bool alpha_mask = false;    // masked or blended materials (-> alpha test in traversal)
    bool transmission = false;  // KHR_materials_transmission
    bool neural = false;        // neural instances (next issue; always false here)

    // Any light that next-event estimation can sample: the shadow pass runs only then.
    bool has_lights() const { return emission || environment; }
    bool operator==(const SceneFeatures&) const = default;
};

// Derives the features from the scene and the environment the render will use (`environment` may
// differ from scene.environment: --env, or the default sky). Emission counts only materials that are
// referenced by a triangle of an instanced mesh.
SceneFeatures derive_features(const Scene& scene, const Environment& environment);

// Specialization constants (ids NB_SC_* in shaders/shared/scene_gpu.h).
std::vector<vk::SpecConstant> specialization(const SceneFeatures& features);

// The passes that one sample wave runs, in order (file names under shaders/), e.g.
// camera_rays, [queue_args, traverse, shade, (queue_args, shadow)] x max_depth, accumulate; resolve.
std::vector<std::string> pass_list(const SceneFeatures& features);

// Multi-line description for `nbvh render --explain`.
std::string explain(const SceneFeatures& features, uint32_t max_depth);

} // namespace nbvh::render
