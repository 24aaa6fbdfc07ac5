// A NeuralModel (engine/neural/model_file.h) on the GPU, and the choice of the neural MLP path
// (issue 4): fp16 weights and hash grid packed two halves per uint (shaders/shared/neural_gpu.h), the
// level table, the encoding box, and the N-BVH cut of every LoD in the two-child node layout
// (NbvhTree::to_gpu_layout, concatenated; leaf refs carry N-BVH node indices).
//
// NeuralEvaluator runs the flat-list query kernels (passes/neural_eval_*.comp) over object-space
// queries: the shader side of the CPU cross-check tests and of the queries/s benchmark.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "engine/neural/model_file.h"
#include "engine/vk/buffer.h"
#include "engine/vk/context.h"
#include "engine/vk/pipeline.h"
#include "shaders/shared/neural_gpu.h"

namespace nbvh::render {

// --neural-path: automatic picks the cooperative-matrix path when the device can run it.
enum class NeuralPath { automatic, scalar, coopmat };
NeuralPath parse_neural_path(std::string_view text); // throws nbvh::Error
const char* neural_path_name(NeuralPath path);

// The kernel variant a device runs for a requested path: "scalar", "coop32" (fp32 accumulators) or
// "coop16". Throws nbvh::Error when coopmat is forced on a device that cannot run it (the message says
// which requirement is missing).
struct NeuralKernelChoice {
    NeuralPath path = NeuralPath::scalar; // resolved: scalar or coopmat
    bool fp32_accumulate = true;          // coopmat only
    std::string describe() const;         // "scalar fp16", "cooperative matrix 16x16x16 fp16->fp32"
};
NeuralKernelChoice choose_neural_kernel(const vk::DeviceFeatures& dev, NeuralPath requested);
// Why the cooperative-matrix path is unavailable ("" when it is available).
std::string coopmat_unavailable_reason(const vk::DeviceFeatures& dev);
// Every cooperative-matrix kernel the device can run, the one `auto` picks first (fp32 accumulators
// where available, then the fp16-accumulator one); empty without cooperative matrices. For tests and
// benchmarks that check each kernel on real hardware.
std::vector<NeuralKernelChoice> coopmat_kernels(const vk::DeviceFeatures& dev);

// Shader of the fp32-accumulating cooperative-matrix kernel: kind "eval" or "query" (MLP loops unrolled,
// subgroup barriers, weight tiles, paired gather of 4 levels at once: results/neural/README.md v8-v17;
// the slower variants measured there are in the git history only).
const char* coopmat_fp32_shader(const char* kind);

// Host-side packing (pure CPU, unit-testable).
std::vector<uint32_t> pack_halves(const std::vector<uint16_t>& halves); // pairs -> words (low = even)
GpuEncodingBox encoding_box_of(const NeuralModel& model);
// Nodes of every LoD and asset concatenated (the subtree of each asset root, model.assets order);
// roots[l * assets + a] = first node of asset a's cut at LoD l. Interior refs are offset so they index
// the concatenated array; leaf refs keep N-BVH node indices.
void pack_lod_nodes(const NeuralModel& model, std::vector<GpuBvhNode>& nodes, std::vector<uint32_t>& roots);
// The weights with every matrix transposed and cut into 16x16 tiles (same matrix offsets as mlp.h;
// element (input c, output r) at nb_coop_weight_slot): each B = W^T tile the cooperative-matrix kernels
// load is 512 contiguous bytes.
std::vector<uint16_t> transpose_mlp(const std::vector<uint16_t>& mlp);

class NeuralModelGpu {
public:
    NeuralModelGpu() = default;
    // Throws nbvh::Error when the model's network sizes differ from the compiled ones.
    NeuralModelGpu(const vk::Context& ctx, const NeuralModel& model);

    const vk::Buffer& levels() const { return levels_; }
    const vk::Buffer& grid() const { return grid_; }
    const vk::Buffer& mlp() const { return mlp_; }
    const vk::Buffer& mlp_transposed() const { return mlp_t_; } // cooperative-matrix kernels
    const vk::Buffer& nodes() const { return nodes_; }      // GpuBvhNode, all LoDs
    // vec3 lo, vec3 hi per N-BVH node, then (from word occupancy_offset()) NB_OCC_WORDS per node and
    // (from word materials_offset()) one material word per node and (from material_fits_offset())
    // NB_NODE_FIT_WORDS per node.
    const vk::Buffer& leaf_bounds() const { return leaf_bounds_; }
    uint32_t occupancy_offset() const { return occupancy_offset_; } // 0: the model has no masks
    uint32_t materials_offset() const { return materials_offset_; } // 0: no node materials
    uint32_t material_fits_offset() const { return material_fits_offset_; } // 0: no material fits
    const GpuEncodingBox& box() const { return box_; }
    uint32_t lod_count() const { return asset_count_ ? uint32_t(roots_.size()) / asset_count_ : 0u; }
    uint32_t asset_count() const { return asset_count_; }
    uint32_t lod_root(uint32_t lod, uint32_t asset = 0) const; // clamps lod to the coarsest
    uint64_t bytes() const { return bytes_; }
    // Hands the buffers to a renderer that binds them by slot (this object keeps box and roots).
    void move_into(vk::Buffer& levels, vk::Buffer& grid, vk::Buffer& mlp, vk::Buffer& mlp_t, vk::Buffer& nodes,
                   vk::Buffer& bounds) {
        levels = std::move(levels_);
        grid = std::move(grid_);
        mlp = std::move(mlp_);
        mlp_t = std::move(mlp_t_);
        nodes = std::move(nodes_);
        bounds = std::move(leaf_bounds_);
    }

private:
    vk::Buffer levels_, grid_, mlp_, mlp_t_, nodes_, leaf_bounds_;
    uint32_t occupancy_offset_ = 0;
    uint32_t materials_offset_ = 0;
    uint32_t material_fits_offset_ = 0;
    GpuEncodingBox box_{};
    std::vector<uint32_t> roots_;
    uint32_t asset_count_ = 0;
    uint64_t bytes_ = 0;
};

// Workgroups per SM of the pipelined split query's gather grids (NeuralEvaluator part 6): H200, 4M
// random queries, 8 chunks, 148feeb: 4, 6 and 8 per SM 2.903 / 2.685 / 2.683 ms (at c5a2e8e, before the
// y-pair gather: 3.190 / 2.959 / 2.966, and 12 and 16 per SM 3.44-3.47; results/neural/). The renderer's split pass is not pipelined: its queries are coherent
// enough that it ran slower so (results/perf/dropped/README.md).
inline constexpr uint32_t SPLIT_GATHER_GROUPS_PER_SM = 6;

// Runs the flat-list query kernels.
class NeuralEvaluator {
public:
    // part (cooperative-matrix kernels only, benchmark breakdown): 0 full, 1 features only, 2 MLP only;
    // the split query (fp32 accumulators): 3 gather kernel then MLP kernel, 4 its gather kernel only,
    // 5 its MLP kernel only (on the features of the last part 3 or 4 dispatch), 6 the split query
    // pipelined (set_pipeline: chunk c's gather beside chunk c - 1's MLP).
    NeuralEvaluator(const vk::Context& ctx, const NeuralModelGpu& model, NeuralKernelChoice choice,
                    uint32_t part = 0);
    const NeuralKernelChoice& choice() const { return choice_; }

    // Decoded hits of `queries` (object space, this model's encoding box).
    std::vector<GpuNeuralHit> evaluate(const std::vector<GpuNeuralQuery>& queries,
                                       float threshold = NB_VISIBILITY_THRESHOLD);
    // GPU milliseconds of one dispatch over `count` queries already uploaded by evaluate() or
    // upload_queries() (timestamps; 0 without). For the benchmark.
    void upload_queries(const std::vector<GpuNeuralQuery>& queries);
    double time_dispatch(uint32_t count, int repetitions, float threshold = NB_VISIBILITY_THRESHOLD);
    // Part 6, the split query pipelined: the queries in `chunks` chunks (fewer for few queries); each
    // chunk's gather kernel is a grid of at most `groups` workgroups looping over the chunk (its
    // residency capped, so that the previous chunk's MLP kernel, recorded after it with no barrier
    // between them, finds room on every SM). The default (pipeline_for): 8 chunks, 6 workgroups per SM;
    // one chunk (the plain split query) where the SM count is unknown. H200: results/neural/README.md.
    struct Pipeline {
        uint32_t chunks = 1, groups = ~0u; // groups ~0u: uncapped
    };
    static Pipeline pipeline_for(const vk::DeviceFeatures& dev);
    void set_pipeline(const Pipeline& p);

private:
    void ensure_capacity(size_t count);
    const vk::Context& ctx_;
    const NeuralModelGpu& model_;
    NeuralKernelChoice choice_;
    uint32_t part_ = 0;
    vk::ComputePipeline pipeline_, gather_;
    vk::Buffer queries_, hits_, features_;
    size_t capacity_ = 0;
    Pipeline pipeline_opts_;
};

} // namespace nbvh::render
