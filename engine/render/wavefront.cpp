#include "engine/render/wavefront.h"
#include "engine/render/wave_plan.h"
#include "engine/render/wavefront_passes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>

#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/scene/camera.h"
#include "shaders/shader_registry.h"
#include "shaders/shared/intersect.h"
#include "shaders/shared/wavefront_gpu.h"

namespace nbvh::render {

using namespace wavefront_passes;

namespace {

template <class T> vk::Buffer upload(const vk::Context& ctx, const std::vector<T>& items, const char* name) {
    return vk::make_buffer(ctx, items, name);
}

void set_camera_params(GpuFrameParams& p, const Camera& camera, float aspect) {
    const CameraBasis basis = camera_basis(camera);
    p.cam_eye = camera.eye;
    p.cam_tan_half_fov = std::tan(0.5f * std::clamp(camera.yfov, 1.0e-3f, 3.1f));
    p.cam_forward = basis.forward;
    p.aspect = aspect;
    p.cam_right = basis.right;
    p.cam_up = basis.up;
}

uint32_t gpu_sampler(Sampler s) { return s == Sampler::sobol ? NB_SAMPLER_SOBOL : NB_SAMPLER_RANDOM; }

} // namespace

WavefrontRenderer::WavefrontRenderer(const vk::Context& ctx, const Scene& scene, const SceneAccel& accel,
                                     const Environment& environment, const Camera& camera,
                                     const RenderOptions& options)
    : ctx_(ctx), scene_(&scene), accel_(&accel), options_(options) {
    if (options_.width == 0 || options_.height == 0 || options_.width > 16384 || options_.height > 16384)
        throw Error(strfmt("image size %ux%u is out of range (1..16384 per side)", options_.width, options_.height));
    if (options_.spp == 0) throw Error("--spp must be at least 1");
    if (options_.max_depth == 0 || options_.max_depth > 256) throw Error("--max-depth must be in 1..256");
    if (!(options_.wave_memory_share > 0.0f && options_.wave_memory_share <= 1.0f))
        throw Error(strfmt("wave memory share %g is out of range (0, 1]", double(options_.wave_memory_share)));
    const vk::DeviceFeatures& dev = ctx_.features();
    if (!dev.scalar_layout) throw Error("the Vulkan device lacks scalarBlockLayout, which every pass needs");
    const uint64_t pixels = uint64_t(options_.width) * options_.height;
    const WaveLimits limits = wave_limits(dev);
    const uint64_t range = limits.buffer_bytes; // one buffer's bytes
    if (pixels * sizeof(vec4) > range)
        throw Error(strfmt("image of %llu pixels exceeds what one buffer of the device holds (%llu MiB)",
                           (unsigned long long)pixels, (unsigned long long)(range >> 20)));
    // Paths per wave and samples of every pixel per wave (wave_plan.h: the deep bounces' latency paid
    // once for several samples, within the device's and the counters' limits).
    const WavePlan plan = plan_wave(pixels, options_, limits);
    capacity_ = plan.capacity;
    wave_samples_ = plan.samples;

    features_ = derive_features(scene, environment);
    // Textures: one texel buffer, or one image each in a sampled-image array (texture_path.h).
    texture_plan_ = plan_textures(texture_caps(dev), scene, features_.textures, options_.texture_path);
    const bool texture_array = texture_plan_.path == TexturePath::array;
    PackOptions pack;
    pack.textures = texture_plan_.path == TexturePath::buffer;
    pack.texel_budget_bytes = texel_budget_bytes(range);
    pack.environment_budget_bytes = range;
    // A hybrid render that never switches to the classical reference leaves the triangles only the model
    // answers for on the host (NeuralRenderOptions::keep_neural_triangles).
    if (options_.neural.model && !options_.neural.classical && !options_.neural.keep_neural_triangles)
        pack.omit_mesh = omitted_neural_meshes(scene);
    data_ = pack_scene(scene, accel, environment, pack);
    triangles_omitted_ = data_.omitted_meshes > 0;
    if (triangles_omitted_)
        log_info("render: %u neural mesh%s not uploaded (%.1f MiB of vertices and triangles%s: the model "
                 "answers for them)",
                 data_.omitted_meshes, data_.omitted_meshes == 1 ? "" : "es",
                 double(data_.omitted_bytes) / double(1 << 20),
                 data_.omitted_unbuilt == data_.omitted_meshes ? ", their BLAS not built"
                 : data_.omitted_unbuilt == 0                  ? " and their BLAS"
                                                               : ", the BLAS of those built");
    if (texture_array) {
        texture_array_ = TextureArray(ctx_, scene.textures);
        texture_plan_.bytes = texture_array_.bytes();
    } else if (texture_plan_.path == TexturePath::buffer) {
        texture_plan_.bytes = uint64_t(data_.texels.size()) * 4;
    }
    // Neural instances: N-BVH + network (hybrid), or triangles with the neural material constants
    // (classical reference); without either they render as plain triangles.
    const NeuralRenderOptions& nopt = options_.neural;
    if (nopt.model || nopt.classical) validate(nopt, scene);
    if (nopt.classical && (nopt.roughness >= 0.0f || nopt.metallic >= 0.0f)) {
        apply_classical_materials(scene, data_, nopt.roughness, nopt.metallic);
        classical_overrides_ = true;
    }
    // The neural instance records (asset, atlas transforms) beside the classical ones: hybrid and
    // classical renders of one scene differ only in which array is bound.
    std::vector<GpuInstance> classical_instances = data_.instances;
    if (nopt.model) features_.neural = mark_neural_instances(scene, accel, *nopt.model, data_) > 0;
    hybrid_ = features_.neural && !nopt.classical;
    features_ = sampled_features(features_, data_); // the lights as packed: no shadow pass without one
    features_ = with_forced(features_, options_.forced_features);

    // Per-render parameters.
    GpuFrameParams& p = params_;
    set_camera_params(p, camera, float(options_.width) / float(options_.height));
    p.width = options_.width;
    p.height = options_.height;
    p.env_width = data_.environment.width;
    p.env_height = data_.environment.height;
    p.env_intensity = data_.environment.intensity;
    p.env_rotation = data_.environment.rotation;
    p.env_inv_mean = data_.environment.inv_mean;
    p.light_count = data_.emissive_light_count;
    p.punctual_count = data_.punctual_light_count;
    p.light_total_power = data_.light_total_power;
    p.max_depth = options_.max_depth;
    p.rr_start_depth = options_.rr_start_depth;
    p.seed = options_.seed;
    p.spp = options_.spp;
    p.wave_capacity = capacity_;
    p.ray_epsilon = NB_RAY_EPSILON_SCALE * data_.scene_extent;
    p.instance_count = accel.tlas.prim_indices.empty() ? 0u : uint32_t(data_.instances.size());
    p.sort_rays = options_.sort_rays ? 1u : 0u;
    p.path_sampler = gpu_sampler(options_.sampler);

    // Buffers, indexed by binding.
    buffers_.resize(NB_BINDING_COUNT);
    buffers_[NB_BIND_PARAMS] = upload(ctx_, std::vector<GpuFrameParams>{params_}, "params");
    buffers_[NB_BIND_COUNTERS] = vk::Buffer(ctx_, sizeof(GpuQueueCounters), vk::MemoryKind::device,
                                            VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, "queue counters");
    buffers_[NB_BIND_TLAS_NODES] = upload(ctx_, data_.tlas_nodes, "tlas nodes");
    buffers_[NB_BIND_BLAS_NODES] = upload(ctx_, data_.blas_nodes, "blas nodes");
    buffers_[NB_BIND_INSTANCES] = upload(ctx_, data_.instances, "instances");
    if (features_.neural) {
        other_instances_ = upload(ctx_, classical_instances, "classical instances");
        if (!hybrid_) std::swap(buffers_[NB_BIND_INSTANCES], other_instances_);
    }
    buffers_[NB_BIND_TRIANGLES] = upload(ctx_, data_.triangles, "triangles");
    buffers_[NB_BIND_VERTICES] = upload(ctx_, data_.vertices, "vertices");
    buffers_[NB_BIND_MATERIALS] = upload(ctx_, data_.materials, "materials");
    buffers_[NB_BIND_TEXTURE_INFOS] = upload(ctx_, data_.texture_infos, "texture infos");
    buffers_[NB_BIND_TEXELS] = upload(ctx_, data_.texels, "texels");
    buffers_[NB_BIND_LIGHTS] = upload(ctx_, data_.lights, "lights");
    buffers_[NB_BIND_LIGHT_CDF] = upload(ctx_, data_.light_cdf, "light cdf");
    buffers_[NB_BIND_ENV] = upload(ctx_, data_.environment.data, "environment");
    buffers_[NB_BIND_RAYS] = vk::Buffer(ctx_, uint64_t(capacity_) * 2 * NB_RAY_WORDS * 4, vk::MemoryKind::device, 0, "rays");
    buffers_[NB_BIND_HITS] = vk::Buffer(ctx_, uint64_t(capacity_) * NB_HIT_WORDS * 4, vk::MemoryKind::device, 0, "hits");
    buffers_[NB_BIND_SHADOW_RAYS] =
        vk::Buffer(ctx_, uint64_t(capacity_) * NB_SHADOW_WORDS * 4, vk::MemoryKind::device, 0, "shadow rays");
    buffers_[NB_BIND_SAMPLE_RADIANCE] =
        vk::Buffer(ctx_, uint64_t(capacity_) * sizeof(vec3), vk::MemoryKind::device, 0, "sample radiance");
    buffers_[NB_BIND_FILM] = vk::Buffer(ctx_, pixels * sizeof(vec4), vk::MemoryKind::device, 0, "film");
    // Pending (ray, leaf) pairs and the neural bindings: sized by the ray capacity in hybrid renders,
    // placeholders otherwise (every pass shares one set-0 layout).
    buffers_[NB_BIND_PENDING_LEAVES] =
        vk::Buffer(ctx_, sizeof(GpuPendingLeaf), vk::MemoryKind::device, 0, "pending leaves");
    NeuralStage::install_placeholders(ctx_, buffers_);
    if (features_.neural) {
        neural_ = std::make_unique<NeuralStage>(ctx_, *nopt.model, scene, nopt, capacity_,
                                                options_.wave_memory_share);
        neural_->install(buffers_);
    }
    buffers_[NB_BIND_OUTPUT] = vk::Buffer(ctx_, pixels * sizeof(vec4), vk::MemoryKind::device, 0, "output");
    // Ray order (NB_RS_*): zero bins, the world bounds the bins are cut from, the two queues' orders.
    buffers_[NB_BIND_RAY_SORT] = vk::Buffer(ctx_, (uint64_t(NB_RS_HEADER_WORDS) + 2ull * capacity_) * 4,
                                            vk::MemoryKind::device, 0, "ray sort");
    buffers_[NB_BIND_RAY_SORT].fill(0u);
    {
        const Aabb wb = scene.world_bounds();
        const glm::vec3 lo = wb.empty() ? glm::vec3(0.0f) : wb.lo, hi = wb.empty() ? glm::vec3(1.0f) : wb.hi;
        const float bounds[8] = {lo.x, lo.y, lo.z, hi.x, hi.y, hi.z, 0.0f, 0.0f};
        buffers_[NB_BIND_RAY_SORT].upload(bounds, sizeof(bounds), uint64_t(NB_RS_BOUNDS) * 4);
    }
    for (uint32_t b : {NB_BIND_COUNTERS, NB_BIND_RAYS, NB_BIND_HITS, NB_BIND_SHADOW_RAYS, NB_BIND_SAMPLE_RADIANCE,
                       NB_BIND_FILM, NB_BIND_PENDING_LEAVES, NB_BIND_OUTPUT})
        buffers_[b].fill(0u);

    // One pipeline per pass, all with the same set-0 layout and the scene's specialization.
    // The texture-array path: binding NB_BIND_TEXELS is the image array, the passes their variants.
    std::vector<vk::Binding> bindings;
    for (uint32_t b = 0; b < NB_NEURAL_BINDING_END; ++b)
        bindings.push_back(texture_array && b == NB_BIND_TEXELS
                               ? vk::Binding{b, vk::BindingType::combined_image_sampler, texture_array_.size()}
                               : vk::Binding{b, vk::BindingType::storage_buffer, 1});
    const std::vector<vk::SpecConstant> spec = specialization(features_);
    for (size_t i = 0; i < PASS_COUNT; ++i) {
        const bool split_pass = i == NEURAL_GATHER || i == NEURAL_MLP;
        if (((i == SHADOW || i == NEURAL_SHADOW) && !features_.has_lights()) ||
            (i >= NEURAL_TRAVERSE && !neural_) ||
            (split_pass && (!neural_ || !neural_->split()))) {
            pipelines_.emplace_back();
            sets_.emplace_back();
            continue; // no shadow pass without anything to sample
        }
        vk::PipelineDesc desc;
        desc.shader = i == NEURAL_QUERY ? neural_->query_shader() : PASS_SHADERS[i];
        if (texture_array) desc.shader = shaders::variant(desc.shader, "texture_array");
        desc.bindings = bindings;
        desc.spec = spec;
        desc.push_constant_bytes = sizeof(GpuPassConstants);
        pipelines_.emplace_back(ctx_, desc);
        vk::DescriptorSet set(ctx_, pipelines_.back());
        for (uint32_t b = 0; b < NB_NEURAL_BINDING_END; ++b)
            if (!(texture_array && b == NB_BIND_TEXELS))
                set.bind(b, split_pass && b == NB_BIND_OUTPUT ? neural_->split_features() : buffers_[b]);
        if (texture_array) texture_array_.bind(set, NB_BIND_TEXELS);
        sets_.push_back(std::move(set));
    }
    make_timer();
    cmd_ = vk::CommandBuffer(ctx_, "wavefront");
    counter_readback_ = vk::Buffer(ctx_, sizeof(GpuQueueCounters) + sizeof(GpuNeuralCounters), vk::MemoryKind::host, 0,
                                   "counter readback");
}

// Another model for the same scene: the neural instances' records (asset index, atlas transforms) are
// marked again for it and the model's buffers replaced; scene, BVHs, queues and pipelines stay.
void WavefrontRenderer::swap_model(const NeuralRenderOptions& n) {
    GpuSceneData marked;
    marked.instances = data_.instances; // the hybrid records: kind, asset and transforms rewritten
    marked.instance_to_scene = data_.instance_to_scene;
    if (mark_neural_instances(*scene_, *accel_, *n.model, marked) == 0)
        throw Error("the model answers no neural instance of the scene");
    neural_->set_model(*n.model, *scene_, n, buffers_); // throws before changing anything on a bad model
    data_.instances = std::move(marked.instances);
    vk::Buffer& hybrid_instances = hybrid_ ? buffers_[NB_BIND_INSTANCES] : other_instances_;
    hybrid_instances.upload(data_.instances);
    for (vk::DescriptorSet& set : sets_)
        if (set.handle() != VK_NULL_HANDLE)
            for (uint32_t b : NeuralStage::model_bindings()) set.bind(b, buffers_[b]);
    ++model_swaps_;
}

// Small images take several samples per submission: a submission's fixed cost (submit, fence wait,
// timestamp and counter read-back) would otherwise dominate (H100, 960x540 classical: ~5.6 ms of wall
// time per sample with one submission each; 8 per submission: 66.0 s wall for 59.6 s of GPU time at
// 16384 spp). Bounded by ~4M path samples per submission, or one wave where a wave holds more, and by
// counter_safe_paths (wave_plan.h: no 32-bit counter can wrap within one submission); an image larger
// than one wave takes one submission per (sample, wave) as before.
void WavefrontRenderer::make_timer() {
    constexpr uint64_t PIXEL_SAMPLES_PER_SUBMISSION = 1u << 22;
    constexpr uint32_t MAX_SAMPLES_PER_SUBMISSION = 32;
    const uint64_t pixels = uint64_t(options_.width) * options_.height;
    samples_per_submission_ =
        pixels > capacity_ ? 1u
                           : uint32_t(std::clamp<uint64_t>(std::min(PIXEL_SAMPLES_PER_SUBMISSION, counter_safe_paths(options_)) /
                                                               std::max<uint64_t>(pixels, 1),
                                                           wave_samples_, std::max(wave_samples_, MAX_SAMPLES_PER_SUBMISSION)));
    const uint32_t waves = (samples_per_submission_ + wave_samples_ - 1) / wave_samples_;
    // A round: args, query (split: gather, MLP and the overflow's fused pass), traversal; path and shadow rays.
    const uint32_t query_passes = std::max(neural_query_passes(), 1u);
    const uint32_t per_round = 2 * (2 + query_passes);
    const uint32_t per_wave =
        2 + (8 + (neural_ ? per_round * neural_->batched_rounds() + 8 : 0)) * options_.max_depth;
    timer_ = vk::GpuTimer(ctx_, 62 + per_wave * waves);
}

bool WavefrontRenderer::apply(const RenderOptions& o) {
    const RenderOptions& c = options_;
    const NeuralRenderOptions &n = o.neural, &cn = c.neural;
    // What needs new buffers or pipelines: the film size and waves, a model where there was none (or
    // none where there was one), the MLP path, the pending-queue size, material overrides baked into a
    // classical reference's triangles, a depth whose rays could wrap a statistics counter within the built
    // wave (wave_plan.h counter_safe_paths). Another model of the same scene is an upload (swap_model).
    const bool overrides = n.roughness >= 0.0f || n.metallic >= 0.0f;
    const bool swap = n.model && cn.model && n.model != cn.model && neural_;
    if (o.width != c.width || o.height != c.height || o.max_wave_pixels != c.max_wave_pixels ||
        o.wave_memory_share != c.wave_memory_share || (n.model != cn.model && !swap) || n.path != cn.path ||
        (n.model && effective_leaves_per_round(n) != neural_->leaves_per_round()) ||
        (n.classical && overrides) != classical_overrides_ ||
        (n.model && !features_.neural && !n.classical) || (n.classical && triangles_omitted_) ||
        n.keep_neural_triangles != cn.keep_neural_triangles || n.split_query != cn.split_query ||
        n.split_chunk_limit != cn.split_chunk_limit || !(o.forced_features == c.forced_features) ||
        capacity_ > counter_safe_paths(o))
        return false;
    if (n.model) validate(n, *scene_);
    if (swap) swap_model(n);
    ++live_updates_;
    options_.max_depth = o.max_depth;
    options_.rr_start_depth = o.rr_start_depth;
    options_.seed = o.seed;
    options_.spp = o.spp;
    params_.max_depth = o.max_depth;
    params_.rr_start_depth = o.rr_start_depth;
    params_.seed = o.seed;
    params_.spp = o.spp;
    options_.sort_rays = o.sort_rays;
    params_.sort_rays = o.sort_rays ? 1u : 0u;
    options_.sampler = o.sampler;
    params_.path_sampler = gpu_sampler(o.sampler);
    buffers_[NB_BIND_PARAMS].upload(&params_, sizeof(params_));
    if (neural_) {
        options_.neural = n;
        neural_->update(n, buffers_[NB_BIND_NEURAL_PARAMS]);
        const bool hybrid = !n.classical;
        if (hybrid != hybrid_) {
            hybrid_ = hybrid;
            std::swap(buffers_[NB_BIND_INSTANCES], other_instances_);
            for (vk::DescriptorSet& set : sets_)
                if (set.handle() != VK_NULL_HANDLE) set.bind(NB_BIND_INSTANCES, buffers_[NB_BIND_INSTANCES]);
        }
    }
    make_timer();
    accumulated_ = 0;
    return true;
}

RenderResult WavefrontRenderer::render() {
    RenderResult result = render_samples(0, options_.spp);
    accumulated_ = options_.spp;
    return result;
}

void WavefrontRenderer::set_camera(const Camera& camera) {
    set_camera_params(params_, camera, float(options_.width) / float(options_.height));
    buffers_[NB_BIND_PARAMS].upload(&params_, sizeof(params_));
    accumulated_ = 0;
}

RenderResult WavefrontRenderer::render_progressive(uint32_t samples, bool read_back) {
    RenderResult result = render_samples(accumulated_, samples, read_back);
    accumulated_ += samples;
    return result;
}

const vk::Buffer& WavefrontRenderer::output() const { return buffers_[NB_BIND_OUTPUT]; }

Image WavefrontRenderer::read_output() const {
    Image image(int(options_.width), int(options_.height), 4);
    buffers_[NB_BIND_OUTPUT].download(image.data.data(), uint64_t(options_.width) * options_.height * sizeof(vec4));
    return image;
}

RenderResult WavefrontRenderer::render_samples(uint32_t first, uint32_t count_samples, bool read_back) {
    const auto t0 = std::chrono::steady_clock::now();
    const uint32_t pixels = options_.width * options_.height;
    if (first == 0) buffers_[NB_BIND_FILM].fill(0u);
    buffers_[NB_BIND_COUNTERS].fill(0u);
    if (neural_) buffers_[NB_BIND_NEURAL_COUNTERS].fill(0u);

    std::vector<std::pair<std::string, double>> pass_ms;
    std::vector<std::vector<double>> depth_ms; // per pass_ms entry, by path depth
    std::map<std::string, size_t> pass_index;
    auto collect = [&] {
        if (!timer_.available()) return;
        for (const vk::GpuTimer::SlotResult& r : timer_.slot_results()) {
            auto it = pass_index.find(r.name);
            if (it == pass_index.end()) {
                it = pass_index.emplace(r.name, pass_ms.size()).first;
                pass_ms.emplace_back(r.name, 0.0);
                depth_ms.emplace_back();
            }
            pass_ms[it->second].second += r.ms;
            std::vector<double>& d = depth_ms[it->second];
            if (d.size() <= r.tag) d.resize(size_t(r.tag) + 1, 0.0);
            d[r.tag] += r.ms;
        }
    };
    // The GPU's statistics counters are 32-bit (neural queries: 64-bit, GpuNeuralCounters) and wrap within
    // a long render (a 1080p frame at 4096 spp traces ~1e10 rays): they are read after every submission
    // (each adds less than 2^32, wave_plan.h counter_safe_paths) and the wrapped differences summed in 64
    // bits. [0..6]: primary, secondary, shadow rays, non-finite samples, neural queries, rounds, leaf-cap
    // rays; then path rays, shadow rays and neural queries per bounce (NB_STAT_DEPTHS each).
    constexpr size_t N = 7 + 3 * NB_STAT_DEPTHS;
    uint64_t totals[N] = {};
    uint64_t last[N] = {};
    // The counters are copied into counter_readback_ at the end of each submission (no extra round trip).
    auto record_counter_copy = [&] {
        cmd_.barrier(vk::Barrier::compute_to_transfer);
        cmd_.copy(buffers_[NB_BIND_COUNTERS], counter_readback_, sizeof(GpuQueueCounters));
        if (neural_)
            cmd_.copy(buffers_[NB_BIND_NEURAL_COUNTERS], counter_readback_, sizeof(GpuNeuralCounters), 0,
                      sizeof(GpuQueueCounters));
        cmd_.barrier(vk::Barrier::compute_to_host);
    };
    auto tally = [&] {
        const char* mapped = static_cast<const char*>(counter_readback_.mapped());
        GpuQueueCounters c;
        std::memcpy(&c, mapped, sizeof(c));
        uint64_t now[N] = {c.rays_primary, c.rays_secondary, c.rays_shadow, c.nonfinite_samples, 0, 0, 0};
        for (uint32_t d = 0; d < NB_STAT_DEPTHS; ++d) {
            now[7 + d] = c.rays_by_depth[d];
            now[7 + NB_STAT_DEPTHS + d] = c.shadow_rays_by_depth[d];
        }
        if (neural_) {
            GpuNeuralCounters nc;
            std::memcpy(&nc, mapped + sizeof(GpuQueueCounters), sizeof(nc));
            now[4] = uint64_t(nc.queries_total_hi) << 32 | nc.queries_total;
            now[5] = nc.rounds;
            now[6] = nc.leaf_cap_rays;
            for (uint32_t d = 0; d < NB_STAT_DEPTHS; ++d)
                now[7 + 2 * NB_STAT_DEPTHS + d] = nc.queries_by_depth[d];
        }
        for (size_t k = 0; k < N; ++k) {
            totals[k] += k == 4 ? now[k] - last[k] : uint32_t(now[k] - last[k]);
            last[k] = now[k];
        }
    };
    // One submission per (sample, wave), or per samples_per_submission_ samples of a one-wave image in
    // waves of wave_samples_ samples (make_timer): bounded command buffers and timer slots at any spp.
    const uint32_t end = first + count_samples;
    for (uint32_t sample = first; sample < end;) {
        for (uint32_t offset = 0; offset < pixels; offset += capacity_) {
            const uint32_t count = std::min(capacity_, pixels - offset);
            const uint32_t samples = offset == 0 && count == pixels ? std::min(samples_per_submission_, end - sample) : 1u;
            cmd_.begin();
            if (timer_.available()) timer_.reset(cmd_.handle());
            for (uint32_t s = 0; s < samples; s += wave_samples_)
                record_sample_wave(cmd_, Wave{sample + s, std::min(wave_samples_, samples - s), offset, count});
            record_counter_copy();
            cmd_.submit_and_wait();
            collect();
            tally();
            if (offset + count >= pixels) sample += samples;
        }
    }
    cmd_.begin();
    if (timer_.available()) timer_.reset(cmd_.handle());
    record_pass(cmd_, RESOLVE, constants(0, 0, Wave{0, 1, 0, pixels}, 0), Dispatch::items, pixels);
    cmd_.barrier(vk::Barrier::compute_to_transfer);
    cmd_.submit_and_wait();
    collect();

    RenderResult result;
    if (read_back) result.image = read_output();
    RenderStats& s = result.stats;
    s.device = ctx_.features().device_name;
    s.driver = ctx_.features().driver_name + " " + ctx_.features().driver_info;
    s.width = options_.width;
    s.height = options_.height;
    s.spp = first + count_samples;
    s.max_depth = options_.max_depth;
    s.pass_ms = pass_ms;
    for (size_t i = 0; i < pass_ms.size(); ++i) s.pass_depth_ms.emplace_back(pass_ms[i].first, depth_ms[i]);
    for (const auto& [name, ms] : pass_ms) s.gpu_ms += ms;
    s.rays_primary = totals[0];
    s.rays_secondary = totals[1];
    s.rays_shadow = totals[2];
    s.nonfinite_samples = totals[3];
    const uint32_t depths = std::min(options_.max_depth, NB_STAT_DEPTHS);
    s.rays_by_depth.assign(totals + 7, totals + 7 + depths);
    s.shadow_rays_by_depth.assign(totals + 7 + NB_STAT_DEPTHS, totals + 7 + NB_STAT_DEPTHS + depths);
    s.texture_path = texture_path_name(texture_plan_.path);
    s.texture_count = texture_plan_.textures;
    s.texture_bytes = texture_plan_.bytes;
    s.texture_halvings = data_.texture_downscales;
    if (hybrid_) {
        s.neural_path = neural_->query_description();
        s.neural_queries = totals[4];
        s.neural_rounds = totals[5];
        s.neural_leaf_cap_rays = totals[6];
        s.neural_queries_by_depth.assign(totals + 7 + 2 * NB_STAT_DEPTHS,
                                         totals + 7 + 2 * NB_STAT_DEPTHS + depths);
        for (const auto& [name, ms] : pass_ms)
            if (name == PASS_SHADERS[NEURAL_QUERY] || name == PASS_SHADERS[NEURAL_GATHER])
                s.neural_query_ms += ms;
    }
    for (size_t i = 0; i < result.image.pixel_count(); ++i) {
        const float* px = result.image.data.data() + i * 4;
        if (!std::isfinite(px[0]) || !std::isfinite(px[1]) || !std::isfinite(px[2])) ++s.nonfinite_pixels;
    }
    s.wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return result;
}

std::vector<TraceHit> WavefrontRenderer::trace(const std::vector<glm::vec3>& origins, const std::vector<glm::vec3>& dirs,
                                               float tmin) {
    NBVH_CHECK(origins.size() == dirs.size());
    std::vector<TraceHit> out;
    out.reserve(origins.size());
    for (size_t first = 0; first < origins.size(); first += capacity_) {
        const uint32_t n = uint32_t(std::min<size_t>(capacity_, origins.size() - first));
        // Queue 0 in SOA layout (wavefront_gpu.h); unused fields stay zero.
        std::vector<uint32_t> words(size_t(capacity_) * NB_RAY_WORDS, 0u);
        for (uint32_t i = 0; i < n; ++i) {
            for (uint32_t c = 0; c < 3; ++c) {
                words[nb_ray_word(0, NB_RAY_ORIGIN, capacity_, i, 3) + c] = floatBitsToUint(origins[first + i][c]);
                words[nb_ray_word(0, NB_RAY_DIR, capacity_, i, 3) + c] = floatBitsToUint(dirs[first + i][c]);
            }
            words[nb_ray_word(0, NB_RAY_T_RESUME, capacity_, i, 1)] = floatBitsToUint(tmin);
        }
        buffers_[NB_BIND_RAYS].upload(words);
        GpuQueueCounters counters{};
        counters.ray_count0 = n;
        buffers_[NB_BIND_COUNTERS].upload(&counters, sizeof(counters));
        if (neural_) buffers_[NB_BIND_NEURAL_COUNTERS].fill(0u);
        cmd_.begin();
        if (timer_.available()) timer_.reset(cmd_.handle());
        record_pass(cmd_, QUEUE_ARGS, constants(0, 0, Wave{0, 1, 0, n}, NB_ARGS_MODE_RAYS), Dispatch::single);
        if (hybrid_) { // as record_sample_wave at depth 0
            record_neural_rounds(cmd_, NEURAL_TRAVERSE, 0, 0, Wave{0, 1, 0, n});
        } else {
            record_pass(cmd_, TRAVERSE, constants(0, 0, Wave{0, 1, 0, n}, 0), Dispatch::indirect_rays);
        }
        cmd_.barrier(vk::Barrier::compute_to_transfer);
        cmd_.submit_and_wait();
        const std::vector<uint32_t> hits = buffers_[NB_BIND_HITS].download<uint32_t>(size_t(capacity_) * NB_HIT_WORDS);
        std::vector<GpuNeuralRayState> states;
        if (hybrid_) states = buffers_[NB_BIND_NEURAL_STATE].download<GpuNeuralRayState>(n);
        for (uint32_t i = 0; i < n; ++i) {
            TraceHit h;
            const uint32_t inst = hits[nb_hit_word(NB_HIT_INSTANCE, capacity_, i, 1)];
            if (inst != NB_NO_HIT && inst < data_.instance_to_scene.size()) {
                h.t = uintBitsToFloat(hits[nb_hit_word(NB_HIT_T, capacity_, i, 1)]);
                h.instance = data_.instance_to_scene[inst];
                const uint32_t tri = hits[nb_hit_word(NB_HIT_TRIANGLE, capacity_, i, 1)];
                if (hybrid_ && tri == NB_NEURAL_TRIANGLE) {
                    h.neural = true;
                    h.normal = states[i].normal;
                    out.push_back(h);
                    continue;
                }
                h.triangle = tri < data_.triangle_to_mesh_triangle.size() ? data_.triangle_to_mesh_triangle[tri] : tri;
                h.u = uintBitsToFloat(hits[nb_hit_word(NB_HIT_BARY, capacity_, i, 2)]);
                h.v = uintBitsToFloat(hits[nb_hit_word(NB_HIT_BARY, capacity_, i, 2) + 1]);
            }
            out.push_back(h);
        }
    }
    return out;
}

} // namespace nbvh::render
