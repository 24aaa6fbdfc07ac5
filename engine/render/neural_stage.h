// The neural part of the wavefront renderer (issue 4): what WavefrontRenderer needs to render a hybrid
// scene (neural instances traced through their N-BVH and queried through the network) or its classical
// reference (the same instances traced from their triangles with the neural material constants).
//
// Per path-ray bounce the renderer records (engine/render/README.md):
//   neural_traverse(op 0, all rays) -> [neural_args -> neural_query -> neural_traverse(op 1, the rays
//   just queried)] x batched rounds -> neural_args -> neural_tail -> shade
// instead of traverse, and for shadow rays
//   neural_shadow(op 0) -> [neural_args -> neural_query -> neural_shadow(op 1)] x batched rounds
//   -> neural_args -> neural_tail -> shadow
// neural_tail finishes the few rays still going after the batched rounds in one pass (scalar queries
// inline), which saves the fixed cost of three dependent dispatches per extra round.
// The pending queue has two halves: a round's traversal reads its rays from the half just queried and
// queues into the other (pass constant mode bit 2, shaders/lib/neural_traverse.glsl).
#pragma once
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "engine/bvh/scene_accel.h"
#include "engine/neural/model_file.h"
#include "engine/render/gpu_scene.h"
#include "engine/render/neural_model_gpu.h"
#include "engine/scene/scene.h"
#include "engine/vk/buffer.h"
#include "engine/vk/context.h"

namespace nbvh::render {

// NeuralRenderOptions::secondary_lod besides a LoD index.
inline constexpr int32_t SECONDARY_LOD_SAME = -1;     // the camera rays' LoD
inline constexpr int32_t SECONDARY_LOD_COARSEST = -2; // the model's coarsest LoD (never finer than lod)
// NeuralRenderOptions::split_min_pairs by default (H200: results/perf/README.md, split_min_pairs_h200/).
inline constexpr uint32_t DEFAULT_SPLIT_MIN_PAIRS = 262144;

// What a neural hit's metallic and roughness come from (engine/neural/node_materials.h).
enum class NeuralMaterials { mix, fit, node, asset };

struct NeuralRenderOptions {
    const NeuralModel* model = nullptr; // hybrid render when set (and not classical)
    bool classical = false;             // reference: neural instances as triangles (the true scene)
    NeuralPath path = NeuralPath::automatic;
    uint32_t lod = 0;                   // N-BVH cut of camera rays (0 = finest)
    int32_t secondary_lod = SECONDARY_LOD_SAME; // cut after the first hit (SECONDARY_LOD_* or an index);
                                                // the CLI's default is SECONDARY_LOD_COARSEST
    // Explicit overrides of the neural surfaces' material (< 0: the asset's glTF material). When set they
    // apply to the classical reference too, so both renders shade alike.
    float roughness = -1.0f;
    float metallic = -1.0f;
    // Leaves queried per ray at most (then the closest hit so far is kept). 8: on the default scene at
    // 1080p, 16 -> 8 -> 6 leaves changed FLIP against the classical reference by < 1e-4 (H200 v3/v4).
    uint32_t max_rounds = 8;
    // The leaf budget of rays after the first hit (and of shadow rays unless max_rounds_shadow), at most
    // max_rounds (0: max_rounds). A truncated secondary ray keeps its closest hit so far (a truncated
    // shadow ray: truncated_shadows_occlusion). 2, with truncated shadow rays blocked (H200, 1080p 16 spp, one call,
    // results/perf/secondary_budget2_h200/): against 4 with shadows passing (the default before), the
    // default scene 1.48x -> 1.29x classical for FLIP 0.0133 -> 0.0185 against the converged reference,
    // the dragon 1.81x -> 1.39x for 0.0031 -> 0.0097, Chess 1.37x -> 1.25x for 0.0305 -> 0.0338.
    // --neural-max-leaves-secondary.
    uint32_t max_rounds_secondary = 2;
    // Leaves queried per shadow ray at most (at most max_rounds; 0: max_rounds_secondary, the default).
    // Apart from the path rays' budget: a truncated shadow ray leaks or blocks light where a truncated
    // path ray changes its path. --neural-max-leaves-shadow.
    uint32_t max_rounds_shadow = 0;
    // A shadow ray truncated by its leaf budget (a leaf with occupied cells left in front of its end) is
    // occluded with this probability (a hash of the ray; 1 block, 0 pass): where blocking darkens and
    // passing brightens, a fraction between them takes light away from some of the rays the unqueried
    // leaves would block. Above 0 the round that spends a shadow ray's budget looks for one leaf more
    // than it queues (no re-traversal). 1 against 0 at budget 2 (same call): FLIP 0.0204 -> 0.0185 on the
    // default scene, 0.0384 -> 0.0338 on Chess, 0.0061 -> 0.0097 on the dragon, for +1 % frame time.
    // --neural-truncated-shadows block|pass|P.
    float truncated_shadows_occlusion = 1.0f;
    // Rounds through the batched query pass; rays still going after them finish in neural_tail (one
    // invocation per ray, scalar queries). Default: all rounds batched (the tail measured slower on the
    // H200: its longest ray serialises ~10 scalar queries per pass).
    uint32_t batched_rounds = 256;
    // Leaves a ray queues per round (1..NB_NL_MAX_LEAVES_PER_ROUND): the next ones in key order in front
    // of its best hit, so one traversal and one query round serve several leaf visits (the extra ones
    // are speculative: their hits cannot beat the closest, same image). --neural-leaves-per-round.
    // 2: fewer wasted speculative queries than 4, fewer rounds than 1, and half the pending pairs of 4,
    // so a 1080p hybrid wave holds 8 samples (H200, 1080p 16 spp, results/perf/knobs_h200.txt: default
    // scene 7.03 -> 6.62 ms per sample, dragon 3.89 -> 3.48 with the 16M-path waves, same images).
    // Rays after the first hit and shadow rays; camera rays take leaves_per_round_camera.
    uint32_t leaves_per_round = 2;
    // Leaves a camera ray queues per round (1..NB_NL_MAX_LEAVES_PER_ROUND; same image for any value).
    // 1: a camera ray's first leaf mostly answers it, so the second leaf that 2 queries beside it is
    // mostly wasted, while rays after the first hit (budget 2) do better with both leaves in one round.
    // H200, 1080p 16 spp, 1 instead of 2: default scene 3.547 -> 3.471 ms per sample, dragon 1.555 ->
    // 1.467, Chess 4.795 -> 4.710, same images (results/perf/camera_round_h200/; 1 for every ray is
    // slower: dragon 1.554 -> 1.650). --neural-leaves-per-round-camera.
    uint32_t leaves_per_round_camera = 1;
    float threshold = NB_VISIBILITY_THRESHOLD;
    // Skip (ray, leaf) pairs whose segment crosses only empty cells of the leaf's occupancy mask
    // (shared/neural_occupancy.h; models without masks query every leaf). --neural-occupancy on|off.
    bool occupancy = true;
    // Metallic/roughness of a hit (engine/neural/node_materials.h): its N-BVH node's fit in the
    // predicted albedo (plus its random spread: mix), the node's mean, or the asset's mean; a model without fits (format 4) falls
    // back to its means, one without either to the asset's. --neural-materials mix|fit|node|asset.
    NeuralMaterials materials = NeuralMaterials::mix;
    // A ray leaving a neural hit seen from behind (predicted normal along the incoming ray) skips
    // back-facing neural hits, so that it leaves the asset instead of bouncing inside it
    // (NB_RAY_BACKFACE_BIT, engine/render/NEURAL.md). --neural-backface-escape on|off.
    bool backface_escape = true;
    // false (a hybrid render that never switches to the classical reference, as `nbvh render --model`):
    // the meshes whose every instance is neural and that emit no light are not uploaded (vertices,
    // triangles, BLAS), so the GPU memory of a hybrid render no longer grows with the triangles the
    // model replaces; such a renderer cannot switch to the classical reference (apply() returns false).
    bool keep_neural_triangles = true;
    // The query pass in two passes where the fp32 cooperative-matrix kernel runs: a gather pass (few
    // registers, many resident subgroups to hide the hash grid's gathers) writes each pair's features,
    // then the MLP pass reads them (shared/neural_gpu.h NB_SPLIT_*; the same features, so the same image);
    // false: the fused pass (gathers and MLP in one kernel). --neural-query split|fused.
    bool split_query = true;
    // At most this many pairs per chunk of the split query pass (0: as many as one buffer holds); tests
    // use it to take a round in several chunks.
    uint32_t split_chunk_limit = 0;
    // A round of fewer pairs than this goes to the fused pass whole: where one dispatch of the fused
    // kernel fills the GPU about once (the last bounces), the split pass's two dispatches cost more than
    // they save. 0: every round takes the split pass. Same image either way. --neural-split-min-pairs.
    uint32_t split_min_pairs = DEFAULT_SPLIT_MIN_PAIRS;
};

// Pending-queue pairs per ray of `options`: the larger of its leaves per round of camera rays and of the
// others (throws nbvh::Error when either is out of range).
uint32_t effective_leaves_per_round(const NeuralRenderOptions& options);
// The leaf budget of rays after the first hit: max_rounds_secondary, at most
// max_rounds (0: max_rounds).
uint32_t effective_secondary_leaves(const NeuralRenderOptions& options);
// The leaf budget of shadow rays: max_rounds_shadow, at most max_rounds (0: effective_secondary_leaves).
uint32_t effective_shadow_leaves(const NeuralRenderOptions& options);

// Throws nbvh::Error on out-of-range constants (roughness/metallic outside [0,1], rounds 0 or > 256,
// LoDs beyond the model's, a model with no neural instance in the scene).
void validate(const NeuralRenderOptions& options, const Scene& scene);

// The model's asset for scene mesh `mesh` (by name, after bind_model_to_scene; a version-1 model's one
// asset answers every neural mesh), or -1.
int32_t asset_of_mesh(const NeuralModel& model, const Scene& scene, uint32_t mesh);
// Marks instances flagged neural as NB_INSTANCE_NEURAL (hybrid render): blas_root becomes the asset
// index, the transforms map world <-> the model's atlas space. Returns how many. Throws nbvh::Error for
// a neural instance whose mesh has no asset in the model.
uint32_t mark_neural_instances(const Scene& scene, const SceneAccel& accel, const NeuralModel& model, GpuSceneData& data);
// Classical reference with explicit overrides: neural meshes' triangles get copies of their materials
// with the override roughness/metallic (< 0: unchanged) and no transmission.
void apply_classical_materials(const Scene& scene, GpuSceneData& data, float roughness, float metallic);

class NeuralStage {
public:
    // memory_share: the renderer's RenderOptions::wave_memory_share; the split query's features buffer
    // takes at most half of it (a renderer's queues take the share, several renderers held at once
    // divide it between them: nbvh study).
    NeuralStage(const vk::Context& ctx, const NeuralModel& model, const Scene& scene,
                const NeuralRenderOptions& options, uint32_t ray_capacity, float memory_share = 0.25f);

    // New per-render neural settings (LoDs, overrides, leaf budget, batched rounds, threshold) written
    // into the params buffer. Leaves per round cannot change here.
    void update(const NeuralRenderOptions& options, vk::Buffer& params_buffer);
    // Another model for the same scene (same network sizes; e.g. a live-training snapshot or a model
    // file of the same assets): its buffers and asset table replace the current ones in `buffers` (the
    // model bindings, NB_BIND_NEURAL_ASSETS and NB_BIND_NEURAL_PARAMS), with `options` applied; the ray
    // state, pending queue and counters stay. Throws nbvh::Error (changing nothing) for a model whose
    // network sizes differ from the renderer's.
    void set_model(const NeuralModel& model, const Scene& scene, const NeuralRenderOptions& options,
                   std::vector<vk::Buffer>& buffers);
    // The bindings set_model() replaces (descriptor sets must be rebound to them).
    static const std::vector<uint32_t>& model_bindings();

    // Moves the neural buffers into `buffers` (indexed by binding, resized to NB_NEURAL_BINDING_END):
    // NB_BIND_NEURAL_*, NB_BIND_NBVH_*, and the pending-leaf queue at NB_BIND_PENDING_LEAVES.
    void install(std::vector<vk::Buffer>& buffers);
    // Small placeholders for every neural binding (scenes rendered without a model).
    static void install_placeholders(const vk::Context& ctx, std::vector<vk::Buffer>& buffers);

    const NeuralKernelChoice& kernel() const { return kernel_; }
    const char* query_shader() const;
    // The split query pass (NeuralRenderOptions::split_query, where the kernel allows): whether it runs,
    // whether the fused pass follows it in a round (NB_QUERY_MODE_OVERFLOW: the pairs past its features
    // buffer where a round can hold more, or a whole round below split_min_pairs), and that buffer (bound at
    // NB_BIND_OUTPUT in the split passes' descriptor sets, lib/bindings.glsl).
    bool split() const { return params_.split_chunk > 0; }
    bool split_overflow() const { return split() && (split_fills_ || params_.split_min_pairs > 0); }
    const vk::Buffer& split_features() const { return split_features_; }
    std::string query_description() const;
    uint32_t rounds() const { return rounds_; }
    // Batched rounds per bounce of camera rays, of rays after the first hit or of shadow rays (each
    // class's leaf budget over its round size); without an argument the largest (command and timer sizing).
    enum class RayClass { camera, path, shadow };
    uint32_t batched_rounds() const { return std::max({batched_, batched_secondary_, batched_shadow_}); }
    uint32_t batched_rounds(RayClass c) const {
        return c == RayClass::camera ? batched_ : c == RayClass::path ? batched_secondary_ : batched_shadow_;
    }
    // Pending-queue pairs per ray (the larger of the two round sizes).
    uint32_t leaves_per_round() const {
        return std::max(params_.leaves_per_round, params_.leaves_per_round_camera);
    }
    const GpuNeuralParams& params() const { return params_; }
    const std::vector<GpuNeuralAsset>& assets() const { return assets_; }

private:
    void set_params(const NeuralRenderOptions& options);
    // The asset table: each asset's subtree root per LoD, the material of the scene mesh it answers
    // and the options' back-face escape (off for a transmissive material).
    static std::vector<GpuNeuralAsset> asset_table(const NeuralModel& model, const NeuralModelGpu& gpu,
                                                   const Scene& scene, const NeuralRenderOptions& options);
    void install_model(std::vector<vk::Buffer>& buffers);

    const vk::Context& ctx_;
    NeuralModelGpu model_;
    NeuralKernelChoice kernel_;
    GpuNeuralParams params_{};
    std::vector<GpuNeuralAsset> assets_;
    uint32_t rounds_ = 0;
    uint32_t batched_ = 0;
    uint32_t batched_secondary_ = 0;
    uint32_t batched_shadow_ = 0;
    uint32_t capacity_ = 0;
    bool split_fills_ = false; // a round can hold more pairs than the features buffer
    vk::Buffer split_features_;
};

// Pairs of a round the split query pass takes (GpuNeuralParams::split_chunk) for `pairs_per_half` pairs
// (a pending half's capacity) with buffers of at most `buffer_bytes`: all of them rounded up to a
// multiple of NB_NEURAL_GROUP, or the most such a multiple whose features fit one buffer (and, when
// `limit` > 0, at most `limit`); 0 (the fused pass) when not one workgroup's features fit.
uint32_t plan_split_query(uint64_t pairs_per_half, uint64_t buffer_bytes, uint64_t limit = 0);

} // namespace nbvh::render
