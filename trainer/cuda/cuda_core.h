// Plain C++ interface between the host glue (cuda_backend.cpp, compiled by g++ with glm) and the
// CUDA side (cuda_core.cu, compiled by nvcc without glm). Only POD arrays and the shared GPU structs
// of shaders/shared/ cross it.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <array>
#include <vector>

#include "engine/neural/shared/training_loss.h"
#include "shaders/shared/hashgrid.h"
#include "shaders/shared/neural_query.h"
#include "shaders/shared/wide_bvh_node.h"

namespace nbvh::cuda {

// Alpha coverage of one triangle of an alpha-tested asset (trainer/ground_truth.cpp alpha_covers).
struct TriCoverage {
    uint32_t mode;     // NB_ALPHA_* of its material
    uint32_t triangle; // original index: the key of its coverage draw, as on the CPU
    float factor;      // base-colour alpha factor (times the texture's alpha where tri_texture has one)
    float cutoff;      // MASK threshold
    uint32_t single_sided; // 1: a BLEND triangle's back face lets every ray through
};

// Normal map of one triangle of an asset with normal-mapped materials (trainer/ground_truth.cpp
// shading_normal, shared/sampling.h nb_normal_map).
struct TriNormalMap {
    int32_t texture;     // index into texture_info (linear data), -1: no normal map
    float scale;         // normalTexture.scale
    float uv[6];         // per vertex, in the normal texture's uv set, its transform applied
    float tangent[12];   // per vertex: xyz, w handedness
};

// Everything about the asset the GPU needs, in flat host arrays (uploaded once, except the base BVH).
struct CoreAsset {
    // Base BVH of the N-BVH cut (CPU node order): regularised boxes (lo xyz, hi xyz) and children
    // (left, right; 0xFFFFFFFF for none). Kept on the host: each cut's compact tree is built from it
    // (cut_tree.h) whenever the cuts change.
    std::vector<float> node_boxes;      // 6 per node
    std::vector<uint32_t> node_children; // 2 per node
    // Triangle BLAS for the ground truth: the renderer's 4-wide layout (to_wide_layout; leaf refs index
    // triangles in leaf order).
    std::vector<GpuWideNode> mesh_wide;
    std::vector<float> tri_vertices;    // 9 per triangle (leaf order)
    std::vector<float> tri_normals;     // 9 per triangle: unit vertex normals (leaf order)
    std::vector<float> tri_albedo;      // 9 per triangle: per-vertex base colour factor
    std::vector<float> tri_uv;          // 6 per triangle: base-colour uvs (texture transform applied)
    std::vector<int32_t> tri_texture;   // per triangle: base-colour texture (index into texture_info) or -1
    std::vector<uint32_t> texels;       // RGBA8 packed, R in the low byte, all textures
    std::vector<uint32_t> texture_info; // 3 per texture: first texel, width, height
    std::array<float, 256> srgb_table{}; // engine/core/image.h srgb_to_linear(i / 255), as the CPU sampler
    std::vector<float> tri_geo_normal;  // 3 per triangle: unit geometric normal (fallback)
    std::vector<TriCoverage> tri_coverage; // per triangle (leaf order); empty: every triangle opaque
    std::vector<TriNormalMap> tri_normal_map; // per triangle (leaf order); empty: no normal maps
    GpuEncodingBox encoding;
    // Parts of a multi-asset run (trainer/training_asset.h TrainingPart): sampling box (lo xyz, extent
    // xyz) and base-BVH root per part; at least one.
    std::vector<float> part_boxes;
    std::vector<uint32_t> part_roots;
    float min_exit = 0.0f;
};

struct CoreConfig {
    std::vector<GpuHashLevel> levels;   // 8 levels
    std::vector<float> grid;            // initial fp32 grid
    std::vector<float> mlp;             // initial fp32 MLP (19456)
    float beta1 = 0.9f, beta2 = 0.999f, epsilon = 1e-8f, l2_reg = 1e-8f, non_matrix_l2_reg = 0.0f;
    bool skip_zero_grad_non_matrix = true;
    // Loss weights (paper 2, 2, 1, 1), linearised normals, visibility masking
    // (engine/neural/shared/training_loss.h; the host sets it from neural::LossConfig).
    GpuLossConfig loss{2.0f, 2.0f, 1.0f, 1.0f, 1u, 1u};
    bool deterministic = false;
    float loss_scale = 128.0f;          // initial per-sample loss scale (power of two)
    // Draw the next step's batch (sampling + ground truth, with this step's keep probabilities) on a
    // second stream while this step's network part runs. The batch is used when the next step has the
    // same step index, batch size, seed and cuts; otherwise it is dropped and the batch drawn anew.
    bool prefetch = true;
};

struct CoreCut {
    std::vector<int32_t> leaf_of_base_node;
    uint32_t leaves = 0;
};

struct CoreStepIn {
    uint32_t step = 0, batch = 0;
    uint64_t seed = 0;
    float learning_rate = 0.0f;         // Adam lr for this optimiser step (schedule applied by the caller)
    const std::vector<float>* keep_probability = nullptr; // cuts[0]
};

struct CoreStepOut {
    double vis = 0, depth = 0, normal = 0, albedo = 0, total = 0; // sums over trained samples
    uint32_t samples = 0, hits = 0;
    uint64_t draws = 0;
    bool skipped = false;
    std::string reason;
    std::vector<double> leaf_loss;
    std::vector<uint32_t> leaf_samples, leaf_draws;
};

// One drawn sample as the GPU saw it (debug / tests).
struct CoreSample {
    float origin[3], dir[3], length;
    int32_t leaf;
    uint32_t cut;
    float target[8];
};

struct CoreTimings { float sample_ms = 0, truth_ms = 0, encode_ms = 0, mlp_ms = 0, grid_bwd_ms = 0, adam_ms = 0; };

class Core {
public:
    virtual ~Core() = default;
    virtual void set_cuts(const std::vector<CoreCut>& cuts) = 0;
    virtual void step(const CoreStepIn& in, CoreStepOut& out) = 0;
    virtual void read_weights(std::vector<float>& mlp, std::vector<float>& grid) const = 0;
    // Debug: the fp16 copies of the weights the kernels read (bits), refreshed by Adam.
    virtual void read_half_weights(std::vector<uint16_t>& mlp, std::vector<uint16_t>& grid) const = 0;
    // Debug: samples and normalised gradients of the last step (call after step()).
    virtual void read_last(std::vector<CoreSample>& samples, std::vector<float>& mlp_grad,
                           std::vector<float>& grid_grad) const = 0;
    virtual float loss_scale() const = 0;
    virtual void set_timing(bool on) = 0;     // per-phase CUDA-event timings (adds syncs)
    virtual CoreTimings timings() const = 0;  // of the last step
};

bool device_available(std::string* name = nullptr); // this thread's current CUDA device
// Makes the CUDA device with this UUID (8-4-4-4-12 hex digits, vk::DeviceFeatures::device_uuid) current on
// the calling thread; false when no CUDA device has it.
bool use_device_uuid(const std::string& uuid);
std::unique_ptr<Core> make_core(const CoreAsset& asset, const CoreConfig& config);

} // namespace nbvh::cuda
