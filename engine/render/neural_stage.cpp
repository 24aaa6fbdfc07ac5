#include "engine/render/neural_stage.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>

#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/neural/asset_table.h"
#include "engine/render/wave_plan.h"
#include "shaders/shared/scene_gpu.h"
#include "shaders/shared/wavefront_gpu.h"

namespace nbvh::render {

uint32_t effective_leaves_per_round(const NeuralRenderOptions& o) {
    const uint32_t k = o.leaves_per_round, k0 = o.leaves_per_round_camera;
    if (k == 0 || k > NB_NL_MAX_LEAVES_PER_ROUND)
        throw Error(strfmt("--neural-leaves-per-round must be in 1..%u", NB_NL_MAX_LEAVES_PER_ROUND));
    if (k0 == 0 || k0 > NB_NL_MAX_LEAVES_PER_ROUND)
        throw Error(strfmt("--neural-leaves-per-round-camera must be in 1..%u", NB_NL_MAX_LEAVES_PER_ROUND));
    return std::max(k, k0);
}

uint32_t effective_secondary_leaves(const NeuralRenderOptions& o) {
    return o.max_rounds_secondary ? std::min(o.max_rounds_secondary, o.max_rounds) : o.max_rounds;
}

uint32_t effective_shadow_leaves(const NeuralRenderOptions& o) {
    return o.max_rounds_shadow ? std::min(o.max_rounds_shadow, o.max_rounds) : effective_secondary_leaves(o);
}

void validate(const NeuralRenderOptions& o, const Scene& scene) {
    effective_leaves_per_round(o);
    if (!(o.roughness <= 1.0f)) throw Error("--neural-roughness must be in [0, 1]");
    if (!(o.metallic <= 1.0f)) throw Error("--neural-metallic must be in [0, 1]");
    if (o.max_rounds == 0 || o.max_rounds > 256) throw Error("--neural-max-leaves must be in 1..256");
    if (o.max_rounds_secondary > 256) throw Error("--neural-max-leaves-secondary must be in 0..256");
    if (o.max_rounds_shadow > 256) throw Error("--neural-max-leaves-shadow must be in 0..256");
    if (!(o.truncated_shadows_occlusion >= 0.0f && o.truncated_shadows_occlusion <= 1.0f))
        throw Error("--neural-truncated-shadows must be block, pass or a probability in [0, 1]");
    if (o.batched_rounds > 256) throw Error("--neural-batched-rounds must be in 0..256");
    if (!(o.threshold > 0.0f && o.threshold < 1.0f)) throw Error("the visibility threshold must be in (0, 1)");
    bool any = false;
    for (const Instance& i : scene.instances) any = any || i.neural;
    if ((o.model || o.classical) && !any) throw Error("the scene has no neural instance (mark one with --neural)");
    if (o.model) {
        const uint32_t lods = std::max(1u, o.model->lod_count);
        if (o.lod >= lods) throw Error(strfmt("--lod %u: the model has %u level(s) of detail (0..%u)", o.lod, lods, lods - 1));
        if (o.secondary_lod < SECONDARY_LOD_COARSEST || o.secondary_lod >= int32_t(lods))
            throw Error(strfmt("--secondary-lod %d: the model has %u level(s) of detail (0..%u)", o.secondary_lod,
                               lods, lods - 1));
    }
}

int32_t asset_of_mesh(const NeuralModel& model, const Scene& scene, uint32_t mesh) {
    if (mesh >= scene.meshes.size()) return -1;
    for (size_t a = 0; a < model.assets.size(); ++a)
        if (model.assets[a].name == scene.meshes[mesh].name) return int32_t(a);
    const bool legacy = model.assets.size() == 1 && model.assets[0].material.empty(); // version 1
    return legacy ? 0 : -1;
}

namespace {
void rows_of(const glm::mat4& m, vec4 rows[3]) {
    for (int r = 0; r < 3; ++r) rows[r] = vec4(m[0][r], m[1][r], m[2][r], m[3][r]);
}
} // namespace

uint32_t mark_neural_instances(const Scene& scene, const SceneAccel& accel, const NeuralModel& model, GpuSceneData& data) {
    uint32_t n = 0;
    for (size_t gi = 0; gi < data.instance_to_scene.size() && gi < data.instances.size(); ++gi) {
        const uint32_t si = data.instance_to_scene[gi];
        const Instance& inst = scene.instances[si];
        if (!inst.neural) continue;
        const int32_t a = asset_of_mesh(model, scene, inst.mesh);
        if (a < 0)
            throw Error(strfmt("neural node '%s' (mesh '%s') has no asset in the model", inst.name.c_str(),
                               scene.meshes[inst.mesh].name.c_str()));
        const ModelAsset& asset = model.assets[size_t(a)];
        // atlas = object * scale + offset (trainer/training_asset.h): composed into the instance.
        glm::mat4 to_atlas(asset.scale);
        to_atlas[3] = glm::vec4(asset.offset, 1.0f);
        GpuInstance& g = data.instances[gi];
        rows_of(to_atlas * accel.world_to_object[si], g.world_to_object);
        rows_of(accel.object_to_world[si] * glm::inverse(to_atlas), g.object_to_world);
        g.kind = NB_INSTANCE_NEURAL;
        g.blas_root = uint32_t(a);
        ++n;
    }
    return n;
}

void apply_classical_materials(const Scene& scene, GpuSceneData& data, float roughness, float metallic) {
    std::map<uint32_t, uint32_t> copy_of; // original material -> its neural-constants copy
    std::vector<bool> done(scene.meshes.size(), false);
    for (size_t gi = 0; gi < data.instance_to_scene.size() && gi < data.instances.size(); ++gi) {
        const Instance& inst = scene.instances[data.instance_to_scene[gi]];
        if (!inst.neural || inst.mesh >= scene.meshes.size() || done[inst.mesh]) continue;
        done[inst.mesh] = true;
        const uint32_t first = data.instances[gi].first_triangle;
        const uint32_t count = scene.meshes[inst.mesh].triangle_count();
        for (uint32_t t = first; t < first + count && t < data.triangles.size(); ++t) {
            const uint32_t m = data.triangles[t].material;
            auto it = copy_of.find(m);
            if (it == copy_of.end()) {
                GpuMaterial c = data.materials[m];
                if (roughness >= 0.0f) c.roughness = roughness;
                if (metallic >= 0.0f) c.metallic = metallic;
                c.metallic_roughness_tex.texture = -1;
                c.transmission = 0.0f;
                it = copy_of.emplace(m, uint32_t(data.materials.size())).first;
                data.materials.push_back(c);
            }
            data.triangles[t].material = it->second;
        }
    }
}

NeuralStage::NeuralStage(const vk::Context& ctx, const NeuralModel& model, const Scene& scene,
                         const NeuralRenderOptions& o, uint32_t ray_capacity, float memory_share)
    : ctx_(ctx), model_(ctx, model), kernel_(choose_neural_kernel(ctx.features(), o.path)),
      rounds_(o.max_rounds), capacity_(ray_capacity) {
    set_params(o);
    assets_ = asset_table(model, model_, scene, o);
    if (o.split_query && kernel_.path == NeuralPath::coopmat && kernel_.fp32_accumulate) {
        // The features buffer: one binding, and at most half the renderer's memory share (an eighth of the
        // GPU's memory by default, beside its queues' quarter); the pairs of a round past it go to the
        // fused pass.
        const WaveLimits limits = wave_limits(ctx.features());
        const uint64_t share =
            uint64_t(double(limits.device_local_bytes) * std::clamp(memory_share, 0.0f, 1.0f) * 0.5);
        const uint64_t bytes =
            limits.device_local_bytes ? std::min(limits.buffer_bytes, share) : limits.buffer_bytes;
        const uint64_t pairs = uint64_t(leaves_per_round()) * std::max(capacity_, 1u);
        params_.split_chunk = plan_split_query(pairs, bytes, o.split_chunk_limit);
        split_fills_ = params_.split_chunk > 0 && params_.split_chunk < pairs;
    }
}

uint32_t plan_split_query(uint64_t pairs_per_half, uint64_t buffer_bytes, uint64_t limit) {
    constexpr uint64_t quad_bytes = 8ull * NB_SPLIT_FEATURE_QUADS;
    const uint64_t group = NB_NEURAL_GROUP;
    uint64_t fit = buffer_bytes / quad_bytes / group * group;
    if (limit > 0) fit = std::min(fit, limit / group * group);
    const uint64_t wanted = (std::max<uint64_t>(pairs_per_half, 1) + group - 1) / group * group;
    return uint32_t(std::min({fit, wanted, uint64_t(0xFFFFFFFFull) / group * group}));
}

std::string NeuralStage::query_description() const {
    std::string d = kernel_.describe();
    if (!split()) return d;
    return d.substr(0, d.find(" (")) + " (split: gather pass + MLP pass, 64 queries per workgroup)";
}

std::vector<GpuNeuralAsset> NeuralStage::asset_table(const NeuralModel& model, const NeuralModelGpu& gpu,
                                                     const Scene& scene, const NeuralRenderOptions& o) {
    // Each asset's subtree root per LoD (LoDs past the model's repeat its coarsest) and the material of
    // the scene mesh it answers (one material per asset after bind_model_to_scene).
    std::vector<GpuNeuralAsset> assets(model.assets.size());
    for (uint32_t a = 0; a < assets.size(); ++a) {
        GpuNeuralAsset& g = assets[a];
        for (uint32_t l = 0; l < NB_NEURAL_MAX_LODS; ++l) g.roots[l] = gpu.lod_root(l, a);
        g.material = 0;
        g.metallic = 0.0f;
        g.roughness = 1.0f;
        g.backface_escape = o.backface_escape ? 1u : 0u;
        for (uint32_t m = 0; m < scene.meshes.size(); ++m)
            if (asset_of_mesh(model, scene, m) == int32_t(a) && !scene.meshes[m].triangle_material.empty()) {
                g.material = scene.meshes[m].triangle_material[0];
                const AssetShading sh = asset_shading(scene, m);
                g.metallic = sh.metallic;
                g.roughness = sh.roughness;
                // Refracted rays see a transmissive asset's surface from inside, and internally
                // reflected ones must stay inside: no escape there (Chess's glass pawn tops,
                // results/perf/README.md).
                if (sh.transmission > 0.0f) g.backface_escape = 0u;
                break;
            }
        if (g.material >= std::max<size_t>(scene.materials.size(), 1)) g.material = 0;
    }
    return assets;
}

void NeuralStage::set_model(const NeuralModel& model, const Scene& scene, const NeuralRenderOptions& o,
                            std::vector<vk::Buffer>& buffers) {
    NeuralModelGpu next(ctx_, model); // throws before anything changes
    std::vector<GpuNeuralAsset> assets = asset_table(model, next, scene, o);
    model_ = std::move(next);
    assets_ = std::move(assets);
    set_params(o);
    install_model(buffers);
}

const std::vector<uint32_t>& NeuralStage::model_bindings() {
    static const std::vector<uint32_t> b = {NB_BIND_NEURAL_LEVELS, NB_BIND_NEURAL_GRID,   NB_BIND_NEURAL_MLP,
                                            NB_BIND_NEURAL_MLP_T,  NB_BIND_NBVH_NODES,    NB_BIND_NBVH_BOUNDS,
                                            NB_BIND_NEURAL_PARAMS, NB_BIND_NEURAL_ASSETS};
    return b;
}

void NeuralStage::set_params(const NeuralRenderOptions& o) {
    rounds_ = o.max_rounds;
    effective_leaves_per_round(o); // validates both round sizes
    params_.leaves_per_round = o.leaves_per_round;
    params_.leaves_per_round_camera = o.leaves_per_round_camera;
    // Every round queues K leaves per ray still going, or finishes it (fewer leaves left in front of its
    // hit): after ceil(budget / K) rounds no ray is left (camera rays: their budget and round size).
    const uint32_t k = params_.leaves_per_round, k0 = params_.leaves_per_round_camera;
    const uint32_t secondary_budget = effective_secondary_leaves(o), shadow_budget = effective_shadow_leaves(o);
    batched_ = std::min((o.max_rounds + k0 - 1) / k0, o.batched_rounds);
    batched_secondary_ = std::min((secondary_budget + k - 1) / k, o.batched_rounds);
    batched_shadow_ = std::min((shadow_budget + k - 1) / k, o.batched_rounds);
    params_.box = model_.box();
    params_.lod_primary = std::min(o.lod, model_.lod_count() - 1);
    const uint32_t coarsest = model_.lod_count() - 1;
    const uint32_t secondary = o.secondary_lod == SECONDARY_LOD_COARSEST ? std::max(o.lod, coarsest)
                               : o.secondary_lod < 0                     ? o.lod
                                                                         : uint32_t(o.secondary_lod);
    params_.lod_secondary = std::min(secondary, coarsest);
    params_.roughness = o.roughness < 0.0f ? -1.0f : o.roughness;
    params_.metallic = o.metallic < 0.0f ? -1.0f : o.metallic;
    params_.threshold = o.threshold;
    params_.max_rounds = o.max_rounds;
    params_.max_rounds_secondary = secondary_budget;
    params_.max_rounds_shadow = shadow_budget;
    params_.truncated_shadows_occlusion = std::clamp(o.truncated_shadows_occlusion, 0.0f, 1.0f);
    params_.split_min_pairs = o.split_min_pairs;
    params_.occupancy = o.occupancy ? model_.occupancy_offset() : 0u;
    params_.materials = o.materials != NeuralMaterials::asset ? model_.materials_offset() : 0u;
    const bool fits = o.materials == NeuralMaterials::fit || o.materials == NeuralMaterials::mix;
    params_.material_fits = fits ? model_.material_fits_offset() : 0u;
    params_.material_spread = o.materials == NeuralMaterials::mix && params_.material_fits != 0u ? 1u : 0u;
}

void NeuralStage::update(const NeuralRenderOptions& o, vk::Buffer& params_buffer) {
    set_params(o);
    params_buffer.upload(&params_, sizeof(params_));
}

const char* NeuralStage::query_shader() const {
    if (kernel_.path == NeuralPath::scalar) return "passes/neural_query_scalar.comp";
    return kernel_.fp32_accumulate ? coopmat_fp32_shader("query") : "passes/neural_query_coop16.comp";
}

void NeuralStage::install_model(std::vector<vk::Buffer>& buffers) {
    if (buffers.size() < NB_NEURAL_BINDING_END) buffers.resize(NB_NEURAL_BINDING_END);
    model_.move_into(buffers[NB_BIND_NEURAL_LEVELS], buffers[NB_BIND_NEURAL_GRID], buffers[NB_BIND_NEURAL_MLP],
                     buffers[NB_BIND_NEURAL_MLP_T], buffers[NB_BIND_NBVH_NODES], buffers[NB_BIND_NBVH_BOUNDS]);
    buffers[NB_BIND_NEURAL_PARAMS] = vk::make_buffer(ctx_, std::vector<GpuNeuralParams>{params_}, "neural params");
    buffers[NB_BIND_NEURAL_ASSETS] = vk::make_buffer(ctx_, assets_, "neural assets");
}

void NeuralStage::install(std::vector<vk::Buffer>& buffers) {
    install_model(buffers);
    // Two halves (ping-pong between a query round and the traversal that follows it) of
    // leaves_per_round() pairs per ray, one binding each (lib/neural_bindings.glsl nb_pending_load).
    const uint64_t half_bytes =
        uint64_t(leaves_per_round()) * std::max(capacity_, 1u) * sizeof(GpuPendingLeaf);
    for (uint32_t b : {NB_BIND_PENDING_LEAVES, NB_BIND_PENDING_LEAVES_1}) {
        buffers[b] = vk::Buffer(ctx_, half_bytes, vk::MemoryKind::device, 0, "pending leaves");
        buffers[b].fill(0u);
    }
    // Path rays at [0, capacity), shadow rays at [capacity, 2 capacity).
    buffers[NB_BIND_NEURAL_STATE] = vk::Buffer(ctx_, 2ull * std::max(capacity_, 1u) * sizeof(GpuNeuralRayState),
                                               vk::MemoryKind::device, 0, "neural ray state");
    buffers[NB_BIND_NEURAL_COUNTERS] = vk::Buffer(ctx_, sizeof(GpuNeuralCounters), vk::MemoryKind::device,
                                                  VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, "neural counters");
    buffers[NB_BIND_NEURAL_STATE].fill(0u);
    buffers[NB_BIND_NEURAL_COUNTERS].fill(0u);
    if (split())
        split_features_ = vk::Buffer(ctx_, uint64_t(params_.split_chunk) * 8u * NB_SPLIT_FEATURE_QUADS,
                                     vk::MemoryKind::device, 0, "split query features");
}

void NeuralStage::install_placeholders(const vk::Context& ctx, std::vector<vk::Buffer>& buffers) {
    if (buffers.size() < NB_NEURAL_BINDING_END) buffers.resize(NB_NEURAL_BINDING_END);
    for (uint32_t b = NB_BIND_NEURAL_LEVELS; b < NB_NEURAL_BINDING_END; ++b) {
        buffers[b] = vk::Buffer(ctx, 64, vk::MemoryKind::device, 0, "neural placeholder");
        buffers[b].fill(0u);
    }
}

} // namespace nbvh::render
