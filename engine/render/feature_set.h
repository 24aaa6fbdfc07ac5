// The scene's feature set: which effects the renderer must simulate (ARCHITECTURE.md "Simulate only
// the effects a scene calls for"). It decides the specialization constants of every pass and which
// passes run at all (no shadow pass without anything to sample, no texture fetch without textures).
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "engine/render/neural_stage.h"
#include "engine/render/texture_path.h"
#include "engine/scene/scene.h"
#include "engine/vk/context.h"
#include "engine/vk/pipeline.h"

namespace nbvh::render {

struct SceneFeatures {
    bool textures = false;      // some material references a texture that exists
    bool normal_maps = false;   // some material has a normal texture
    bool emission = false;      // emissive triangles (-> emissive next-event estimation)
    bool environment = false;   // an environment (map or constant) lights the scene (-> env NEE)
    bool alpha_mask = false;    // masked or blended materials (-> alpha test in traversal)
    bool transmission = false;  // KHR_materials_transmission
    bool neural = false;        // hybrid render: neural instances answered by the model's N-BVH + MLP
    bool punctual = false;      // KHR_lights_punctual lights of positive intensity (-> punctual NEE)
    bool single_sided = false;  // some material is single-sided (-> back-face culling in traversal)

    // Any light that next-event estimation can sample: the shadow pass runs only then.
    bool has_lights() const { return emission || environment || punctual; }
    bool operator==(const SceneFeatures&) const = default;
};

// The features a render can be forced to simulate although the scene lacks them (RenderOptions::
// forced_features; tests/render/bench_features.cpp measures what each specialization saves): every
// flag but `neural`. Forcing one never changes the image, only the work: the shaders test per material,
// texture and light whether an effect applies (a texture index >= 0, an alpha mode, double_sided, a
// transmission weight, light counts, an environment of positive mean), so a forced flag adds those
// tests, the UV interpolation, the next-event strategy and the shadow pass, and nothing more.
struct ForcibleFeature {
    const char* name;             // "textures", "normal_maps", ... (the SceneFeatures member's name)
    bool SceneFeatures::*flag;
};
const std::vector<ForcibleFeature>& forcible_features();
SceneFeatures all_forcible_features(); // every flag of forcible_features() set
// `derived` with every flag of `forced` turned on as well; throws nbvh::Error when `forced` asks for
// `neural` (a hybrid render needs a model, not a flag).
SceneFeatures with_forced(SceneFeatures derived, const SceneFeatures& forced);

// Derives the features from the scene, the environment the render will use (`environment` may differ
// from scene.environment: --env, the default sky, or none with --env none) and the neural options (neural: a model is given,
// not --classical, and some instance is neural). Emission counts only materials that are referenced by a
// triangle of an instanced mesh.
SceneFeatures derive_features(const Scene& scene, const Environment& environment,
                              const NeuralRenderOptions& neural = {});

// The features of a packed scene that next-event estimation can really sample (WavefrontRenderer applies
// it to derive_features()): emission only with an emissive triangle of positive area outside outline
// shells (GpuSceneData::emissive_light_count), punctual lights only with positive power, the environment
// only with a positive mean (a map of black texels lights nothing). The shadow pass runs iff has_lights().
SceneFeatures sampled_features(SceneFeatures derived, const GpuSceneData& data);

// What the neural stage of a hybrid render runs (engine/render/NEURAL.md), read from a NeuralStage.
struct NeuralPlan {
    std::string kernel;            // MLP path, NeuralKernelChoice::describe()
    std::string query_shader;      // shader of the batched query pass (the fused one)
    bool split_query = false;      // the query pass as neural_gather + neural_query_mlp32 (--neural-query)
    bool split_fused_rest = false; // ... and the fused pass after them (NeuralStage::split_overflow)
    uint32_t lod_primary = 0, lod_secondary = 0, lod_count = 1; // N-BVH cuts (0 = finest) of the model
    uint32_t leaf_budget = 0;              // leaves queried per camera ray at most (--neural-max-leaves)
    uint32_t leaf_budget_secondary = 0;    // ... per ray after the first hit (--neural-max-leaves-secondary)
    uint32_t leaf_budget_shadow = 0;       // ... per shadow ray (--neural-max-leaves-shadow)
    float truncated_shadows_occlusion = 0; // truncated shadow rays occluded with it (--neural-truncated-shadows)
    uint32_t batched_rounds_secondary = 0; // batched rounds of their bounces
    uint32_t batched_rounds_shadow = 0;    // ... of shadow rays
    uint32_t leaves_per_round = 0;        // leaves a ray after the first hit or a shadow ray queues per round
    uint32_t leaves_per_round_camera = 0; // ... a camera ray
    uint32_t batched_rounds = 0;   // rounds through the batched query pass before neural_tail
    bool occupancy = false;        // leaves skipped by the model's occupancy masks (on and the model has them)
    bool model_has_masks = false;
    bool backface_escape = false;  // --neural-backface-escape
    bool node_materials = false;   // hits shaded with their node's metallic/roughness (on and the model has them)
    bool material_fits = false;    // ... as the node's fit in the predicted albedo (fit and the model has them)
    bool model_has_materials = false, model_has_fits = false;
    bool fits_requested = false;   // --neural-materials mix (the default) or fit
    bool material_spread = false;  // ... plus the fit's spread (mix and the model has fits)
    uint32_t instances = 0, assets = 0;
};

// For a hybrid render (neural.model set, not classical): validates the options and builds the
// renderer's NeuralStage on `ctx` as WavefrontRenderer does (kernel choice for the device, LoD clamping,
// rounds), so --explain prints what the render will run; throws the errors the render would. nullopt
// without a hybrid render (`ctx` may then be null).
std::optional<NeuralPlan> plan_neural(const vk::Context* ctx, const Scene& scene, const NeuralRenderOptions& neural);

// Specialization constants (ids NB_SC_* in shaders/shared/scene_gpu.h).
std::vector<vk::SpecConstant> specialization(const SceneFeatures& features);

// The passes that one sample wave runs, in order (file names under shaders/), e.g.
// camera_rays, [queue_args, ray_sort, traverse, shade, (queue_args, ray_sort, shadow)] x max_depth, accumulate; resolve;
// one bounce listed. Hybrid renders (`neural`) traverse through the neural rounds (neural_stage.h).
std::vector<std::string> pass_list(const SceneFeatures& features, const NeuralPlan* neural = nullptr);

// Multi-line description for `nbvh render --explain`: the features (with `textures`: the texture path
// and its memory), the neural stage, the passes.
std::string explain(const SceneFeatures& features, uint32_t max_depth, const NeuralPlan* neural = nullptr,
                    const TexturePlan* textures = nullptr);

} // namespace nbvh::render
