#include "engine/render/neural_model_gpu.h"

#include <algorithm>
#include <optional>

#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/render/neural_grid_pack.h"
#include "engine/vk/commands.h"
#include "shaders/shared/mlp.h"
#include "shaders/shared/neural_occupancy.h"

namespace nbvh::render {

NeuralPath parse_neural_path(std::string_view text) {
    if (text == "auto") return NeuralPath::automatic;
    if (text == "scalar") return NeuralPath::scalar;
    if (text == "coopmat") return NeuralPath::coopmat;
    throw Error(strfmt("--neural-path must be auto, scalar or coopmat (got '%.*s')", int(text.size()), text.data()));
}

const char* neural_path_name(NeuralPath path) {
    switch (path) {
    case NeuralPath::automatic: return "auto";
    case NeuralPath::scalar: return "scalar";
    case NeuralPath::coopmat: return "coopmat";
    }
    return "?";
}

std::string NeuralKernelChoice::describe() const {
    if (path == NeuralPath::scalar) return "scalar fp16 (one query per invocation)";
    return fp32_accumulate ? "cooperative matrix 16x16x16 fp16 -> fp32 (fused, 64 queries per workgroup)"
                           : "cooperative matrix 16x16x16 fp16 -> fp16 (fused, 64 queries per workgroup)";
}

namespace {
bool has_shape(const vk::DeviceFeatures& dev, VkComponentTypeNV acc) {
    for (const vk::CoopMatrixShape& s : dev.coop_matrix_shapes)
        if (s.m == 16 && s.n == 16 && s.k == 16 && s.a == VK_COMPONENT_TYPE_FLOAT16_NV &&
            s.b == VK_COMPONENT_TYPE_FLOAT16_NV && s.c == acc && s.d == acc && s.scope == VK_SCOPE_SUBGROUP_NV)
            return true;
    return false;
}
} // namespace

std::vector<NeuralKernelChoice> coopmat_kernels(const vk::DeviceFeatures& dev) {
    std::vector<NeuralKernelChoice> out;
    if (!coopmat_unavailable_reason(dev).empty()) return out;
    out.push_back(choose_neural_kernel(dev, NeuralPath::coopmat));
    if (out[0].fp32_accumulate && has_shape(dev, VK_COMPONENT_TYPE_FLOAT16_NV)) {
        out.push_back(out[0]);
        out.back().fp32_accumulate = false;
    }
    return out;
}

std::string coopmat_unavailable_reason(const vk::DeviceFeatures& dev) {
    if (!dev.coop_matrix_nv) return "the device lacks VK_NV_cooperative_matrix";
    if (!dev.fp16) return "the device lacks shaderFloat16";
    if (!dev.storage16) return "the device lacks storageBuffer16BitAccess";
    if (dev.subgroup_size != NB_NEURAL_COOP_SUBGROUP)
        return strfmt("the cooperative-matrix kernel needs subgroups of %u (device: %u)", NB_NEURAL_COOP_SUBGROUP,
                      dev.subgroup_size);
    if (!dev.subgroup_shuffle) return "the device lacks subgroup shuffles in compute shaders";
    if (dev.max_shared_memory < 18u * 1024u) return "the device has less than 18 KiB of shared memory";
    if (!has_shape(dev, VK_COMPONENT_TYPE_FLOAT32_NV) && !has_shape(dev, VK_COMPONENT_TYPE_FLOAT16_NV))
        return "the device has no 16x16x16 fp16 cooperative-matrix shape";
    return "";
}

NeuralKernelChoice choose_neural_kernel(const vk::DeviceFeatures& dev, NeuralPath requested) {
    NeuralKernelChoice c;
    const std::string why = coopmat_unavailable_reason(dev);
    if (requested == NeuralPath::scalar || (requested == NeuralPath::automatic && !why.empty())) {
        c.path = NeuralPath::scalar;
        return c;
    }
    if (!why.empty()) throw Error("--neural-path coopmat: " + why);
    c.path = NeuralPath::coopmat;
    c.fp32_accumulate = has_shape(dev, VK_COMPONENT_TYPE_FLOAT32_NV);
    return c;
}

std::vector<uint32_t> pack_halves(const std::vector<uint16_t>& halves) {
    std::vector<uint32_t> words((halves.size() + 1) / 2, 0u);
    for (size_t i = 0; i < halves.size(); ++i) words[i / 2] |= uint32_t(halves[i]) << (16 * (i & 1));
    return words;
}

std::vector<uint16_t> transpose_mlp(const std::vector<uint16_t>& mlp) {
    NBVH_CHECK(mlp.size() == NB_MLP_WEIGHT_COUNT);
    std::vector<uint16_t> t(mlp.size());
    for (uint32_t m = 0; m < NB_MLP_MATRICES; ++m) {
        const uint32_t ins = nb_mlp_layer_inputs(m), outs = nb_mlp_layer_outputs(m), off = nb_mlp_layer_offset(m);
        for (uint32_t r = 0; r < outs; ++r)
            for (uint32_t c = 0; c < ins; ++c) t[off + nb_coop_weight_slot(outs, c, r)] = mlp[nb_mlp_weight_index(m, r, c)];
    }
    return t;
}

GpuEncodingBox encoding_box_of(const NeuralModel& model) {
    return nb_make_encoding_box(model.encoding_box.lo, model.encoding_box.hi);
}

void pack_lod_nodes(const NeuralModel& model, std::vector<GpuBvhNode>& nodes, std::vector<uint32_t>& roots) {
    nodes.clear();
    roots.clear();
    const NbvhTree tree = model.tree();
    for (uint32_t lod = 0; lod < std::max(1u, model.lod_count); ++lod) {
        for (const ModelAsset& a : model.assets) {
            const uint32_t base = uint32_t(nodes.size());
            roots.push_back(base);
            for (GpuBvhNode n : tree.to_gpu_layout(lod, a.root)) {
                if (n.left != NB_CHILD_NONE && !nb_is_leaf(n.left)) n.left += base;
                if (n.right != NB_CHILD_NONE && !nb_is_leaf(n.right)) n.right += base;
                // Grown to contain the dilated leaf intervals below (walk culling, shared/neural_gpu.h);
                // an absent child's empty box (lo > hi) stays empty.
                if (n.left != NB_CHILD_NONE) nb_neural_cull_bounds(n.lmin, n.lmax);
                if (n.right != NB_CHILD_NONE) nb_neural_cull_bounds(n.rmin, n.rmax);
                nodes.push_back(n);
            }
        }
    }
}

NeuralModelGpu::NeuralModelGpu(const vk::Context& ctx, const NeuralModel& model) {
    const NeuralConfig& c = model.cfg;
    if (c.grid_levels != NB_GRID_MAX_LEVELS || c.grid_features != NB_GRID_FEATURES ||
        c.segment_points != NB_SEGMENT_POINTS || c.mlp_width != NB_MLP_WIDTH ||
        c.mlp_hidden_layers != NB_MLP_HIDDEN_LAYERS || c.mlp_outputs != NB_MLP_OUTPUTS)
        throw Error("the model's network sizes differ from the renderer's (8 levels x 4 features, 3 points, "
                    "64 wide, 4 hidden layers, 8 outputs)");
    if (model.levels.size() != NB_GRID_MAX_LEVELS || model.mlp.size() != NB_MLP_WEIGHT_COUNT || model.grid.empty() ||
        model.nodes.empty())
        throw Error("the model has no network or no N-BVH");
    std::vector<uvec4> packed_levels;
    for (const GpuHashLevel& l : model.levels) packed_levels.push_back(nb_level_pack(l)); // neural_grid.glsl
    const PackedGrid grid = pack_grid(model, ctx.features().max_storage_buffer_range); // one binding
    packed_levels.push_back(ypair_word(grid)); // NB_LEVEL_YPAIR_WORD
    levels_ = vk::make_buffer(ctx, packed_levels, "neural levels");
    grid_ = vk::make_buffer(ctx, grid.words, "neural grid");
    mlp_ = vk::make_buffer(ctx, pack_halves(model.mlp), "neural mlp");
    mlp_t_ = vk::make_buffer(ctx, pack_halves(transpose_mlp(model.mlp)), "neural mlp transposed");
    std::vector<GpuBvhNode> nodes;
    pack_lod_nodes(model, nodes, roots_);
    asset_count_ = uint32_t(model.assets.size());
    nodes_ = vk::make_buffer(ctx, nodes, "nbvh nodes");
    // (lo, 0), (hi, 0) per node as words (NB_NBVH_BOUNDS_WORDS: two 16-byte loads, neural_bindings.glsl),
    // then the occupancy masks (shared/neural_occupancy.h) and the node materials (node_materials.h) in
    // the same buffer (the set has no binding to spare: lavapipe allows 32 storage buffers per stage);
    // models without them have none.
    std::vector<uint32_t> words;
    words.reserve(model.nodes.size() * NB_NBVH_BOUNDS_WORDS + model.occupancy.size() +
                  model.node_materials.size() + model.material_fits.size());
    for (const NbvhNode& n : model.nodes)
        for (const glm::vec3& v : {n.bounds.lo, n.bounds.hi}) {
            for (int k = 0; k < 3; ++k) words.push_back(floatBitsToUint(v[k]));
            words.push_back(0u);
        }
    if (model.occupancy.size() == model.nodes.size() * NB_OCC_WORDS) {
        occupancy_offset_ = uint32_t(words.size());
        words.insert(words.end(), model.occupancy.begin(), model.occupancy.end());
    }
    if (model.node_materials.size() == model.nodes.size()) {
        materials_offset_ = uint32_t(words.size());
        words.insert(words.end(), model.node_materials.begin(), model.node_materials.end());
    }
    if (model.material_fits.size() == model.nodes.size() * NB_NODE_FIT_WORDS) {
        material_fits_offset_ = uint32_t(words.size());
        words.insert(words.end(), model.material_fits.begin(), model.material_fits.end());
    }
    leaf_bounds_ = vk::make_buffer(ctx, words, "nbvh node bounds, occupancy and materials");
    box_ = encoding_box_of(model);
    bytes_ = levels_.size() + grid_.size() + mlp_.size() + mlp_t_.size() + nodes_.size() + leaf_bounds_.size();
}

uint32_t NeuralModelGpu::lod_root(uint32_t lod, uint32_t asset) const {
    NBVH_CHECK(!roots_.empty() && asset < asset_count_);
    return roots_[size_t(std::min(lod, lod_count() - 1)) * asset_count_ + asset];
}

const char* coopmat_fp32_shader(const char* kind) {
    return std::string(kind) == "eval" ? "passes/neural_eval_coop32.comp" : "passes/neural_query_coop32.comp";
}

namespace {
const char* eval_shader(const NeuralKernelChoice& c) {
    if (c.path == NeuralPath::scalar) return "passes/neural_eval_scalar.comp";
    return c.fp32_accumulate ? coopmat_fp32_shader("eval") : "passes/neural_eval_coop16.comp";
}
// Part 6 of NeuralEvaluator: chunk c's gather (a grid of at most p.groups workgroups looping over the
// chunk) recorded before chunk c - 1's MLP with no barrier between them; a barrier after each pair.
void record_pipelined(vk::CommandBuffer& cmd, const vk::ComputePipeline& gather, vk::DescriptorSet& gather_set,
                      const vk::ComputePipeline& mlp, vk::DescriptorSet& set, GpuNeuralEvalPush push,
                      uint32_t count, const NeuralEvaluator::Pipeline& p) {
    const uint32_t groups = (count + NB_NEURAL_GROUP - 1) / NB_NEURAL_GROUP;
    if (groups == 0) return;
    const uint32_t chunks = std::min(p.chunks, groups);
    const uint32_t per_chunk = (groups + chunks - 1) / chunks; // workgroups (>= 1)
    const uint32_t n = (groups + per_chunk - 1) / per_chunk;
    auto range = [&](uint32_t c) {
        GpuNeuralEvalPush q = push;
        q.first = c * per_chunk * NB_NEURAL_GROUP;
        q.count = std::min(count, (c + 1) * per_chunk * NB_NEURAL_GROUP);
        return q;
    };
    for (uint32_t c = 0; c <= n; ++c) {
        if (c < n) {
            const GpuNeuralEvalPush q = range(c);
            const uint32_t g = (q.count - q.first + NB_NEURAL_GROUP - 1) / NB_NEURAL_GROUP;
            cmd.bind(gather, gather_set).push(q).dispatch(std::min(g, p.groups));
        }
        if (c > 0) {
            const GpuNeuralEvalPush q = range(c - 1);
            cmd.bind(mlp, set).push(q).dispatch_items(q.count - q.first, NB_NEURAL_GROUP);
        }
        cmd.barrier(vk::Barrier::compute_to_compute);
    }
}
} // namespace

NeuralEvaluator::NeuralEvaluator(const vk::Context& ctx, const NeuralModelGpu& model,
                                 NeuralKernelChoice choice, uint32_t part)
    : ctx_(ctx), model_(model), choice_(choice), part_(part), pipeline_opts_(pipeline_for(ctx.features())) {
    NBVH_CHECK(part <= 6);
    const bool split = part >= 3;
    NBVH_CHECK(!split || (choice_.path == NeuralPath::coopmat && choice_.fp32_accumulate));
    vk::PipelineDesc desc;
    desc.shader = split ? "passes/neural_eval_mlp32.comp" : eval_shader(choice_);
    for (uint32_t b = 0; b <= (split ? NB_NEVAL_BIND_FEATURES : NB_NEVAL_BIND_HITS); ++b)
        desc.bindings.push_back({b, vk::BindingType::storage_buffer, 1});
    desc.push_constant_bytes = sizeof(GpuNeuralEvalPush);
    if (choice_.path == NeuralPath::coopmat) desc.spec = {{0, split ? 0u : part}};
    pipeline_ = vk::ComputePipeline(ctx_, desc);
    if (split) {
        desc.shader = "passes/neural_eval_gather.comp";
        desc.spec = {};
        gather_ = vk::ComputePipeline(ctx_, desc);
    }
}

void NeuralEvaluator::ensure_capacity(size_t count) {
    if (count <= capacity_) return;
    capacity_ = std::max<size_t>(count, 64);
    queries_ = vk::Buffer(ctx_, capacity_ * sizeof(GpuNeuralQuery), vk::MemoryKind::device, 0, "neural queries");
    hits_ = vk::Buffer(ctx_, capacity_ * sizeof(GpuNeuralHit), vk::MemoryKind::device, 0, "neural hits");
    if (part_ >= 3)
        features_ = vk::Buffer(ctx_, (capacity_ + NB_NEURAL_GROUP) * NB_SPLIT_FEATURE_QUADS * 8u,
                               vk::MemoryKind::device, 0, "neural features");
}

void NeuralEvaluator::upload_queries(const std::vector<GpuNeuralQuery>& queries) {
    ensure_capacity(queries.size());
    if (!queries.empty()) queries_.upload(queries.data(), queries.size() * sizeof(GpuNeuralQuery));
}

std::vector<GpuNeuralHit> NeuralEvaluator::evaluate(const std::vector<GpuNeuralQuery>& queries, float threshold) {
    if (queries.empty()) return {};
    upload_queries(queries);
    time_dispatch(uint32_t(queries.size()), 1, threshold);
    return hits_.download<GpuNeuralHit>(queries.size());
}

double NeuralEvaluator::time_dispatch(uint32_t count, int repetitions, float threshold) {
    NBVH_CHECK(count <= capacity_);
    auto make_set = [&](const vk::ComputePipeline& p) {
        vk::DescriptorSet set(ctx_, p);
        set.bind(NB_NEVAL_BIND_LEVELS, model_.levels())
            .bind(NB_NEVAL_BIND_GRID, model_.grid())
            .bind(NB_NEVAL_BIND_MLP,
                  choice_.path == NeuralPath::coopmat ? model_.mlp_transposed() : model_.mlp())
            .bind(NB_NEVAL_BIND_QUERIES, queries_)
            .bind(NB_NEVAL_BIND_HITS, hits_);
        if (part_ >= 3) set.bind(NB_NEVAL_BIND_FEATURES, features_);
        return set;
    };
    vk::DescriptorSet set = make_set(pipeline_);
    std::optional<vk::DescriptorSet> gather_set;
    if (part_ >= 3) gather_set.emplace(make_set(gather_));
    GpuNeuralEvalPush push{};
    push.box = model_.box();
    push.count = count;
    push.threshold = threshold;
    vk::CommandBuffer cmd(ctx_, "neural eval");
    vk::GpuTimer timer(ctx_, 2 * std::max(1, repetitions) + 2);
    cmd.begin();
    if (timer.available()) timer.reset(cmd.handle());
    // As many untimed dispatches first: the GPU's clock ramps up under load (H200: the SM clock, sampled
    // during a benchmark run, fell to 1260-1440 instead of 1980 MHz while the host compared results
    // between rows; results/neural/README.md).
    const int total = repetitions > 1 ? 2 * repetitions : 1;
    for (int r = 0; r < total; ++r) {
        const bool timed = r >= total - std::max(1, repetitions);
        cmd.begin_pass("neural eval", timer.available() && timed ? &timer : nullptr);
        if (part_ == 6) {
            record_pipelined(cmd, gather_, *gather_set, pipeline_, set, push, count, pipeline_opts_);
        } else if (part_ == 3 || part_ == 4) {
            cmd.bind(gather_, *gather_set).push(push).dispatch_items(count, NB_NEURAL_GROUP);
            if (part_ == 3) cmd.barrier(vk::Barrier::compute_to_compute);
        }
        if (part_ != 4 && part_ != 6) cmd.bind(pipeline_, set).push(push).dispatch_items(count, NB_NEURAL_GROUP);
        cmd.end_pass();
        cmd.barrier(vk::Barrier::compute_to_compute);
    }
    cmd.barrier(vk::Barrier::compute_to_transfer);
    cmd.submit_and_wait();
    double ms = 0.0;
    if (timer.available())
        for (const auto& [name, t] : timer.results()) ms += t;
    return ms / std::max(1, repetitions);
}

void NeuralEvaluator::set_pipeline(const Pipeline& p) {
    NBVH_CHECK(p.chunks >= 1 && p.groups >= 1);
    pipeline_opts_ = p;
}

NeuralEvaluator::Pipeline NeuralEvaluator::pipeline_for(const vk::DeviceFeatures& dev) {
    Pipeline p;
    if (dev.sm_count == 0) return p; // one chunk, the gather grid as large as the chunk (uncapped)
    // H200 (132 SMs), 4M random queries, 148feeb (the y-pair gather): 8 chunks 2.685 ms against 3.190 for
    // the plain split query; 4 and 16 chunks 2.711 / 2.780 (results/neural/bench_neural_random_h200.txt;
    // at c5a2e8e, before the y-pair gather, 2.959 / 2.990 / 3.069 against 3.547).
    p.chunks = 8;
    p.groups = SPLIT_GATHER_GROUPS_PER_SM * dev.sm_count;
    return p;
}

} // namespace nbvh::render
