// The wavefront path tracer: owns the scene buffers, the per-ray SOA queues and one compute pipeline
// per stage, and records the pass sequence (README.md here):
//   camera_rays -> [queue_args -> (ray_sort) -> traverse -> shade -> (queue_args -> ray_sort -> shadow)] x max_depth
//   -> accumulate ... per sample and wave of pixels, then resolve once (ray_sort: --sort-rays, not camera rays).
// The Vulkan context owns device things; the Scene/SceneAccel stay with the caller.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "engine/bvh/scene_accel.h"
#include "engine/core/image.h"
#include "engine/render/feature_set.h"
#include "engine/render/gpu_scene.h"
#include "engine/render/neural_stage.h"
#include "engine/render/texture_array.h"
#include "engine/render/texture_path.h"
#include "shaders/shared/wavefront_gpu.h"
#include "engine/scene/scene.h"
#include "engine/vk/buffer.h"
#include "engine/vk/commands.h"
#include "engine/vk/context.h"
#include "engine/vk/pipeline.h"

namespace nbvh::render {

// The paths' random numbers (RenderOptions::sampler).
enum class Sampler { sobol, random };
inline const char* sampler_name(Sampler s) { return s == Sampler::random ? "random" : "sobol"; }

struct RenderOptions {
    uint32_t width = 640, height = 480;
    uint32_t spp = 16;
    uint32_t max_depth = 8;          // path segments (1: emitters and environment seen directly)
    uint32_t seed = 0;
    uint32_t rr_start_depth = 3;     // Russian roulette from this segment on
    // Paths per wave (rays per queue), further bounded by the device (one buffer's bytes, a quarter of
    // its memory, the dispatch limits) and the statistics counters; a wave of several samples of every
    // pixel holds at most 32M paths (engine/render/wave_plan.h). 32M: sixteen samples of a 1080p frame,
    // so the deep bounces' latency-bound passes are paid once per sixteen samples (results/perf/
    // frame_depths.md, README.md). Queue memory at 32M: ~6.5 GB classical, ~17.2 GB hybrid (2 leaves per
    // round), bounded by a quarter of the GPU's memory.
    uint32_t max_wave_pixels = 1u << 25;
    // Share of the GPU's device-local memory the wave's queues may take (wave_plan.h): a lone renderer a
    // quarter; `nbvh study`'s image renderers, which live together, split half of it between them.
    float wave_memory_share = 0.25f;
    // Secondary and shadow rays are traced bin by bin of (direction level per axis, origin cell) (shared/
    // wavefront_gpu.h NB_RS_*, passes/ray_sort.comp; the hybrid's neural traversal op 0 too): same image,
    // coherent warps. --sort-rays.
    bool sort_rays = true;
    // The paths' random numbers (lib/path_sampler.glsl): Owen-scrambled Sobol pairs per pixel (default;
    // lower variance at the same spp) or independent PCG numbers. --sampler.
    Sampler sampler = Sampler::sobol;
    NeuralRenderOptions neural;      // hybrid (model) or classical-reference render of neural instances
    // Texel buffer or sampled-image array (texture_path.h): auto takes the array where the device can.
    TexturePathRequest texture_path = TexturePathRequest::automatic;
    // Effects simulated although the scene lacks them (feature_set.h with_forced: same image, more
    // work); benchmarks only. The texture path is still chosen from the scene's own features.
    SceneFeatures forced_features;
};

struct RenderStats {
    std::string device, driver;
    uint32_t width = 0, height = 0, spp = 0, max_depth = 0;
    std::vector<std::pair<std::string, double>> pass_ms; // summed GPU time per pass (timestamps)
    // The same per path depth (index = bounce: 0 for camera rays and the per-sample passes); each
    // pass's entries sum to its pass_ms. Tells deep bounces' small dispatches from the first ones.
    std::vector<std::pair<std::string, std::vector<double>>> pass_depth_ms;
    double gpu_ms = 0.0;           // sum of the passes
    double wall_ms = 0.0;          // host time of render(), submissions included
    uint64_t rays_primary = 0, rays_secondary = 0, rays_shadow = 0;
    // Path rays and shadow rays per bounce (index = depth, min(max_depth, NB_STAT_DEPTHS) entries, the
    // last also counting deeper bounces): with pass_depth_ms, the time per ray of each bounce.
    std::vector<uint64_t> rays_by_depth, shadow_rays_by_depth;
    uint64_t nonfinite_samples = 0; // dropped by accumulate.comp
    uint64_t nonfinite_pixels = 0;  // in the resolved image (counted on the CPU; must be 0)
    // Textures (texture_path.h): the path that ran, its textures and their GPU bytes (buffer: the texel
    // buffer; array: the images' allocations), halvings to fit the buffer's budget.
    std::string texture_path;
    uint32_t texture_count = 0, texture_halvings = 0;
    uint64_t texture_bytes = 0;
    // Neural (hybrid renders): queries of path rays, rounds with queued pairs, the MLP path, and the
    // GPU time of the neural query passes (queries/s = neural_queries / neural_query_ms).
    std::string neural_path;
    uint64_t neural_queries = 0, neural_rounds = 0;
    std::vector<uint64_t> neural_queries_by_depth; // per bounce, as rays_by_depth (their sum: neural_queries)
    uint64_t neural_leaf_cap_rays = 0;             // rays that spent their leaf budget (it may have cut them)
    double neural_query_ms = 0.0;
    double neural_queries_per_ray() const {
        const uint64_t r = rays_primary + rays_secondary;
        return r ? double(neural_queries) / double(r) : 0.0;
    }
    double neural_queries_per_second() const {
        return neural_query_ms > 0.0 ? double(neural_queries) / (neural_query_ms * 1.0e-3) : 0.0;
    }
    uint64_t rays_total() const { return rays_primary + rays_secondary + rays_shadow; }
    double rays_per_second() const { return gpu_ms > 0.0 ? double(rays_total()) / (gpu_ms * 1.0e-3) : 0.0; }
};

struct RenderResult {
    Image image; // linear RGBA float, alpha 1
    RenderStats stats;
};

// A closest hit from the GPU traversal, in scene terms (for tests against the CPU traversal).
struct TraceHit {
    float t = NB_INF;
    uint32_t instance = 0xFFFFFFFFu; // Scene::instances index; 0xFFFFFFFF: miss
    uint32_t triangle = 0xFFFFFFFFu; // original triangle index in the instance's mesh (neural: 0xFFFFFFFF)
    float u = 0.0f, v = 0.0f;
    bool neural = false;             // answered by the network (hybrid renderers)
    glm::vec3 normal{0.0f};          // neural hits: the predicted world-space unit normal
};

class WavefrontRenderer {
public:
    // `environment` is the one to light with (scene's, --env, or default_sky()); `camera` the view.
    WavefrontRenderer(const vk::Context& ctx, const Scene& scene, const SceneAccel& accel, const Environment& environment,
                      const Camera& camera, const RenderOptions& options);

    const SceneFeatures& features() const { return features_; }
    const GpuSceneData& scene_data() const { return data_; }
    const TexturePlan& texture_plan() const { return texture_plan_; } // bytes: as allocated

    // Renders options.spp samples per pixel and reads the mean radiance back.
    RenderResult render();

    // Progressive rendering (the interactive viewer, app/viewer/): `set_camera` changes the view of
    // later samples and clears the film; `render_progressive` adds `samples` samples per pixel to the
    // film and reads back the running mean (stats: rays and times of this call; spp = samples so far).
    // With read_back false the mean stays on the GPU (result.image is empty): output() holds it, for a
    // display pass (the viewer), and read_output() fetches it later.
    void set_camera(const Camera& camera);
    // Settings without a rebuild (the viewer's sliders): path depth, Russian roulette, seed, spp, and
    // with a model: hybrid <-> classical, LoDs, leaf budget, batched rounds, visibility threshold and the
    // material overrides of neural hits are uploads (params buffers, the bound instance array). Returns
    // false, changing nothing, when `options` differ in what needs new buffers or pipelines (size,
    // waves, a model where there was none or the reverse, MLP path, leaves per round, overrides baked
    // into a classical reference): build a new renderer then. Another model for the same scene (same
    // assets; a live-training snapshot, a retrained file) is an upload too: its buffers and asset table
    // replace the old ones and the neural instance records are marked again; scene, BVHs, queues and
    // pipelines stay. Clears the film. Throws nbvh::Error on invalid neural options or a model that does
    // not answer the scene (changing nothing).
    bool apply(const RenderOptions& options);
    uint64_t live_updates() const { return live_updates_; } // successful apply() calls
    uint64_t model_swaps() const { return model_swaps_; }   // of which replaced the model
    bool hybrid() const { return hybrid_; }
    RenderResult render_progressive(uint32_t samples = 1, bool read_back = true);
    uint32_t accumulated_samples() const { return accumulated_; }
    // Linear RGBA32F mean radiance of the last render, width*height pixels, rows top to bottom.
    const vk::Buffer& output() const;
    uint32_t width() const { return options_.width; }
    uint32_t height() const { return options_.height; }
    Image read_output() const;

    // Closest hits of world-space rays (org, dir; t in [tmin, inf)) through passes/traverse.comp, or, in
    // a hybrid renderer, through the same neural rounds as camera rays (primary LoD, leaf budget and
    // leaves per round of the options): triangles and neural leaves, closest accepted hit.
    // Query passes per round: 1 (the fused pass), 2 (the split pass's gather and MLP passes) or 3 (and the
    // fused pass for the pairs past the split pass's features buffer, or for a whole round below
    // split_min_pairs); 0 without a model.
    uint32_t neural_query_passes() const;
    std::vector<TraceHit> trace(const std::vector<glm::vec3>& origins, const std::vector<glm::vec3>& dirs, float tmin = 0.0f);

private:
    // One wave: `samples` samples (from `sample`) of the pixels [offset, offset + count), one path each.
    struct Wave {
        uint32_t sample = 0, samples = 1, offset = 0, count = 0;
    };
    GpuPassConstants constants(uint32_t queue, uint32_t depth, const Wave& w, uint32_t mode) const;
    // indirect_split / indirect_overflow: GpuNeuralCounters::split_dispatch / overflow_dispatch.
    enum class Dispatch { items, single, indirect_rays, indirect_shadow, indirect_pending, indirect_split, indirect_overflow };
    void record_pass(vk::CommandBuffer& cmd, size_t pass, const GpuPassConstants& pc, Dispatch dispatch,
                     uint64_t items = 0);
    // The query pass of one round: fused, or the split pass's gather and MLP passes (and the fused pass
    // for the pairs past the split pass's features buffer).
    void record_query(vk::CommandBuffer& cmd, const GpuPassConstants& pc);
    void record_sample_wave(vk::CommandBuffer& cmd, const Wave& w);
    void record_neural_rounds(vk::CommandBuffer& cmd, size_t traverse_pass, uint32_t q, uint32_t depth, const Wave& w);
    // Records passes/ray_sort.comp for the path queue q (not camera rays) or the shadow queue when the
    // ray order is on; returns whether the traversal that follows reads the order.
    bool record_ray_sort(vk::CommandBuffer& cmd, uint32_t q, uint32_t depth, const Wave& w, bool shadow);
    // Samples [first, first + count) into the film (cleared when first == 0), then resolve + read back.
    RenderResult render_samples(uint32_t first, uint32_t count, bool read_back = true);

    void make_timer();
    void swap_model(const NeuralRenderOptions& options);

    const vk::Context& ctx_;
    const Scene* scene_ = nullptr; // the caller's, outlives the renderer (validation in apply())
    const SceneAccel* accel_ = nullptr; // the caller's too (instance transforms for a model swap)
    RenderOptions options_;
    SceneFeatures features_;
    TexturePlan texture_plan_;
    GpuSceneData data_;
    TextureArray texture_array_; // the texture-array path's images (texture_plan_.path == array)
    GpuFrameParams params_{};
    uint32_t capacity_ = 0;
    uint32_t wave_samples_ = 1;           // samples per wave of a one-wave image (constructor)
    uint32_t samples_per_submission_ = 1; // make_timer
    uint32_t accumulated_ = 0; // samples per pixel in the film (progressive rendering)

    std::vector<vk::Buffer> buffers_;          // indexed by NB_BIND_*
    std::vector<vk::ComputePipeline> pipelines_; // indexed by Pass
    std::vector<vk::DescriptorSet> sets_;
    std::unique_ptr<NeuralStage> neural_; // renders with a model (hybrid or its classical reference)
    bool hybrid_ = false;                 // neural instances through the N-BVH (else their triangles)
    bool classical_overrides_ = false;    // the classical reference's triangles carry material overrides
    bool triangles_omitted_ = false;      // neural-only meshes not uploaded (keep_neural_triangles false)
    vk::Buffer other_instances_;          // the instance array not bound (classical <-> hybrid)
    uint64_t live_updates_ = 0, model_swaps_ = 0;
    vk::GpuTimer timer_;
    vk::CommandBuffer cmd_;
    // Host-visible copy of the queue and neural counters, written by each sample's own submission
    // (two blocking downloads with fresh staging buffers per sample before).
    vk::Buffer counter_readback_;
};

} // namespace nbvh::render
