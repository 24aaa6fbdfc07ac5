// Host glue of the CUDA backend: flattens the TrainingAsset for the GPU, keeps the cut uploads in
// sync with StepParams::cut_version, applies the Adam learning-rate schedule and turns the device's
// sums into StepStats (trainer/trainer_backend.h contract, same as the CPU backend).
#include "trainer/cuda/cuda_backend.h"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "engine/bvh/wide_bvh.h"
#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/neural/adam.h"
#include "engine/neural/losses.h"
#include "engine/scene/texture_sampler.h"
#include "trainer/cuda/cuda_core.h"

namespace nbvh {
namespace {

// The normal map of triangle `tri` (original index) of `m`; `slot` uploads a texture once and returns
// its device index.
template <class Slot>
cuda::TriNormalMap normal_map_of(const Scene& scene, const Mesh& m, const Material* material, uint32_t tri,
                                 Slot&& slot) {
    cuda::TriNormalMap nm{-1, 1.0f, {}, {}};
    if (!material || material->normal_tex.texture < 0 || size_t(material->normal_tex.texture) >= scene.textures.size())
        return nm; // the CPU's fallback texel (0.5, 0.5, 1) leaves the normal as it is
    const std::vector<glm::vec2>& uvs = material->normal_tex.uv_set == 1u ? m.uv1 : m.uv0;
    if (uvs.size() != m.positions.size()) return nm;
    nm.texture = slot(uint32_t(material->normal_tex.texture));
    nm.scale = material->normal_scale;
    const uint32_t* idx = &m.indices[size_t(tri) * 3];
    for (int c = 0; c < 3; ++c) {
        const glm::vec3 uv = material->normal_tex.transform * glm::vec3(uvs[idx[c]], 1.0f);
        nm.uv[2 * c] = uv.x;
        nm.uv[2 * c + 1] = uv.y;
        for (int q = 0; q < 4; ++q) nm.tangent[4 * c + q] = m.tangents[idx[c]][q];
    }
    return nm;
}

cuda::CoreAsset flatten_asset(const TrainingAsset& asset) {
    cuda::CoreAsset a;
    const Bvh& base = asset.bvh();
    a.node_boxes.reserve(base.nodes.size() * 6);
    a.node_children.reserve(base.nodes.size() * 2);
    for (size_t i = 0; i < base.nodes.size(); ++i) {
        const Aabb& b = asset.node_boxes[i];
        for (int k = 0; k < 3; ++k) a.node_boxes.push_back(b.lo[k]);
        for (int k = 0; k < 3; ++k) a.node_boxes.push_back(b.hi[k]);
        a.node_children.push_back(base.nodes[i].left);
        a.node_children.push_back(base.nodes[i].right);
    }
    a.mesh_wide = to_wide_layout(asset.mesh_bvh.bvh);
    const Mesh& m = *asset.mesh;
    const Scene& scene = *asset.scene;
    const MeshBvh& mb = asset.mesh_bvh;
    const uint32_t tris = mb.triangle_count();
    a.tri_vertices.resize(size_t(tris) * 9);
    a.tri_normals.resize(size_t(tris) * 9);
    a.tri_albedo.resize(size_t(tris) * 9);
    a.tri_geo_normal.resize(size_t(tris) * 3);
    a.tri_uv.assign(size_t(tris) * 6, 0.0f);
    a.tri_texture.assign(tris, -1);
    // Base-colour textures used by the asset, packed RGBA8 (R in the low byte), uploaded once.
    std::vector<int32_t> slot_of(scene.textures.size(), -1);
    auto texture_slot = [&](uint32_t t) {
        if (slot_of[t] < 0) {
            const Texture& tex = scene.textures[t];
            slot_of[t] = int32_t(a.texture_info.size() / 3);
            const bool ok = tex.width > 0 && tex.height > 0 && tex.rgba8.size() >= size_t(tex.width) * tex.height * 4;
            a.texture_info.push_back(uint32_t(a.texels.size()));
            a.texture_info.push_back(ok ? tex.width : 1u);
            a.texture_info.push_back(ok ? tex.height : 1u);
            if (!ok) a.texels.push_back(0xFFFFFFFFu);
            else
                for (size_t p = 0; p < size_t(tex.width) * tex.height; ++p)
                    a.texels.push_back(uint32_t(tex.rgba8[4 * p]) | (uint32_t(tex.rgba8[4 * p + 1]) << 8) |
                                       (uint32_t(tex.rgba8[4 * p + 2]) << 16) | (uint32_t(tex.rgba8[4 * p + 3]) << 24));
        }
        return slot_of[t];
    };
    for (int i = 0; i < 256; ++i) a.srgb_table[size_t(i)] = srgb_to_linear(float(i) / 255.0f);
    // Normal maps (ground_truth.cpp shading_normal): where a material has one and the mesh has tangents.
    bool normal_maps = false;
    if (m.tangents.size() == m.positions.size())
        for (uint32_t t = 0; t < m.triangle_count() && !normal_maps; ++t) {
            const uint32_t mat = t < m.triangle_material.size() ? m.triangle_material[t] : 0u;
            normal_maps = mat < scene.materials.size() && scene.materials[mat].normal_tex.texture >= 0;
        }
    const bool has_normals = m.normals.size() == m.positions.size();
    for (uint32_t k = 0; k < tris; ++k) {
        const uint32_t tri = mb.bvh.prim_indices[k];
        const uint32_t* idx = &m.indices[size_t(tri) * 3];
        const uint32_t mat = tri < m.triangle_material.size() ? m.triangle_material[tri] : 0u;
        const Material* material = mat < scene.materials.size() ? &scene.materials[mat] : nullptr;
        const uint32_t uv_set = material ? material->base_color_tex.uv_set : 0u;
        const std::vector<glm::vec2>& uvs = uv_set == 1u ? m.uv1 : m.uv0;
        // Base-colour texture of the triangle (device index) and its uvs with the texture transform
        // applied (affine: exact under interpolation); the kernel samples it per hit, as the CPU does.
        int32_t dev_tex = -1;
        if (material && material->base_color_tex.texture >= 0 && uvs.size() == m.positions.size() &&
            size_t(material->base_color_tex.texture) < scene.textures.size())
            dev_tex = texture_slot(uint32_t(material->base_color_tex.texture));
        a.tri_texture[k] = dev_tex;
        if (normal_maps) a.tri_normal_map.push_back(normal_map_of(scene, m, material, tri, texture_slot));
        if (asset.alpha_tested) {
            const bool tested = material && material->alpha_mode != AlphaMode::opaque;
            a.tri_coverage.push_back(cuda::TriCoverage{tested ? uint32_t(material->alpha_mode) : 0u, tri,
                                                 tested ? material->base_color.w : 1.0f,
                                                 tested ? material->alpha_cutoff : 0.0f,
                                                 tested && !material->double_sided ? 1u : 0u});
        }
        for (int c = 0; c < 3; ++c) {
            const glm::vec3 p = mb.vertices[size_t(k) * 3 + c];
            const glm::vec3 n = has_normals ? m.normals[idx[c]] : glm::vec3(0.0f);
            glm::vec3 al(0.9f); // official default material base colour when none is given (notes §6.7)
            if (material) al = glm::vec3(material->base_color);
            if (dev_tex >= 0) {
                const glm::vec3 uv = material->base_color_tex.transform * glm::vec3(uvs[idx[c]], 1.0f);
                a.tri_uv[size_t(k) * 6 + c * 2] = uv.x;
                a.tri_uv[size_t(k) * 6 + c * 2 + 1] = uv.y;
            }
            if (!std::isfinite(al.x + al.y + al.z)) al = glm::vec3(0.9f);
            for (int q = 0; q < 3; ++q) {
                a.tri_vertices[size_t(k) * 9 + c * 3 + q] = p[q];
                a.tri_normals[size_t(k) * 9 + c * 3 + q] = n[q];
                a.tri_albedo[size_t(k) * 9 + c * 3 + q] = al[q];
            }
        }
        const glm::vec3 p0 = mb.vertices[size_t(k) * 3], p1 = mb.vertices[size_t(k) * 3 + 1],
                        p2 = mb.vertices[size_t(k) * 3 + 2];
        glm::vec3 g = glm::cross(p1 - p0, p2 - p0);
        const float gl = glm::length(g);
        g = gl > 0.0f && std::isfinite(gl) ? g / gl : glm::vec3(0.0f, 0.0f, 1.0f);
        for (int q = 0; q < 3; ++q) a.tri_geo_normal[size_t(k) * 3 + q] = g[q];
    }
    a.encoding = asset.encoding;
    for (const TrainingPart& p : asset.parts) {
        const glm::vec3 lo = p.sampling_box.lo, ext = p.sampling_box.extent();
        for (int k = 0; k < 3; ++k) a.part_boxes.push_back(lo[k]);
        for (int k = 0; k < 3; ++k) a.part_boxes.push_back(ext[k]);
        a.part_roots.push_back(p.root);
    }
    a.min_exit = asset.min_exit;
    return a;
}

class CudaBackend final : public CudaTrainerBackend {
public:
    CudaBackend(const TrainingAsset& asset, const NeuralConfig& config, const neural::AdamConfig& adam,
                const CudaBackendOptions& options, uint64_t seed)
        : asset_(asset), adam_(adam) {
        weights_ = neural::create_network(config, seed); // same init as the CPU backend for a seed
        cuda::CoreConfig c;
        c.levels = weights_.levels;
        c.grid = weights_.grid;
        c.mlp = weights_.mlp;
        c.beta1 = adam.beta1;
        c.beta2 = adam.beta2;
        c.epsilon = adam.epsilon;
        c.l2_reg = adam.l2_reg;
        c.non_matrix_l2_reg = adam.non_matrix_l2_reg;
        c.skip_zero_grad_non_matrix = adam.skip_zero_grad_non_matrix;
        // Paper weights, linearised normals, masking (as the CPU backend).
        c.loss = neural::to_gpu(neural::LossConfig{});
        c.deterministic = options.deterministic;
        c.prefetch = options.prefetch;
        c.loss_scale = options.loss_scale;
        if (!(c.loss_scale >= 1.0f && c.loss_scale <= 65536.0f)) throw Error("CUDA loss scale must be in [1, 65536]");
        try {
            core_ = cuda::make_core(flatten_asset(asset), c);
        } catch (const std::runtime_error& e) {
            throw Error(std::string("CUDA backend: ") + e.what());
        }
    }

    const char* name() const override { return "cuda"; }

    StepStats step(const StepParams& params) override {
        NBVH_CHECK(!params.cuts.empty() && params.cuts[0] != nullptr);
        if (params.cuts.size() > NB_CUDA_MAX_CUTS_HOST) throw Error("CUDA backend: at most 8 levels of detail");
        if (params.cut_version != cut_version_ || !cuts_uploaded_ || params.cuts.size() != cut_count_) {
            std::vector<cuda::CoreCut> cuts(params.cuts.size());
            for (size_t k = 0; k < params.cuts.size(); ++k) {
                cuts[k].leaf_of_base_node = params.cuts[k]->leaf_of_base_node;
                cuts[k].leaves = uint32_t(params.cuts[k]->size());
            }
            core_->set_cuts(cuts);
            cut_version_ = params.cut_version;
            cut_count_ = params.cuts.size();
            cuts_uploaded_ = true;
        }
        cuda::CoreStepIn in;
        in.step = params.step;
        in.batch = params.batch_size;
        in.seed = params.seed;
        in.learning_rate = neural::lr_at_step(adam_, adam_steps_);
        in.keep_probability = &params.cuts[0]->keep_probability;
        cuda::CoreStepOut o;
        try {
            core_->step(in, o);
        } catch (const std::runtime_error& e) {
            throw Error(std::string("CUDA backend: ") + e.what());
        }
        StepStats st;
        st.samples = o.samples;
        st.hits = o.hits;
        st.draws = o.draws;
        st.skipped = o.skipped;
        st.skip_reason = o.reason;
        st.leaves.resize(o.leaf_loss.size());
        for (size_t i = 0; i < st.leaves.size(); ++i) {
            st.leaves[i].loss_sum = o.leaf_loss[i];
            st.leaves[i].samples = o.leaf_samples[i];
            st.leaves[i].draws = o.leaf_draws[i];
        }
        if (o.samples > 0) {
            const double inv = 1.0 / double(o.samples), inv_hits = o.hits ? 1.0 / double(o.hits) : 0.0;
            st.loss.visibility = o.vis * inv;
            st.loss.depth = o.depth * inv_hits;
            st.loss.normal = o.normal * inv_hits;
            st.loss.albedo = o.albedo * inv_hits;
            st.loss.total = o.total * inv;
        }
        if (!st.skipped) adam_steps_++;
        weights_dirty_ = true;
        return st;
    }

    void read_weights(neural::NetworkWeights& out) const override {
        out = weights_; // config and level table
        core_->read_weights(out.mlp, out.grid);
    }

    void read_half_weights(std::vector<uint16_t>& mlp, std::vector<uint16_t>& grid) const override {
        core_->read_half_weights(mlp, grid);
    }

    void read_last_step(std::vector<CudaDebugSample>& samples, std::vector<float>& mlp_grad,
                        std::vector<float>& grid_grad) const override {
        std::vector<cuda::CoreSample> cs;
        core_->read_last(cs, mlp_grad, grid_grad);
        samples.resize(cs.size());
        for (size_t i = 0; i < cs.size(); ++i) {
            samples[i].origin = glm::vec3(cs[i].origin[0], cs[i].origin[1], cs[i].origin[2]);
            samples[i].dir = glm::vec3(cs[i].dir[0], cs[i].dir[1], cs[i].dir[2]);
            samples[i].length = cs[i].length;
            samples[i].leaf = cs[i].leaf;
            samples[i].cut = cs[i].cut;
            for (int k = 0; k < 8; ++k) samples[i].target[k] = cs[i].target[k];
        }
    }
    void set_timing(bool on) override { core_->set_timing(on); }
    CudaPhaseTimes phase_times() const override {
        const cuda::CoreTimings t = core_->timings();
        return CudaPhaseTimes{t.sample_ms, t.truth_ms, t.encode_ms, t.mlp_ms, t.grid_bwd_ms, t.adam_ms};
    }
    float loss_scale() const override { return core_->loss_scale(); }

private:
    static constexpr size_t NB_CUDA_MAX_CUTS_HOST = 8;
    const TrainingAsset& asset_;
    neural::AdamConfig adam_;
    neural::NetworkWeights weights_;
    std::unique_ptr<cuda::Core> core_;
    uint64_t cut_version_ = 0, adam_steps_ = 0;
    size_t cut_count_ = 0;
    bool cuts_uploaded_ = false, weights_dirty_ = false;
};

} // namespace

std::string cuda_device_name() {
    std::string name;
    return cuda::device_available(&name) ? name : std::string();
}

bool cuda_backend_available() { return cuda::device_available(nullptr); }

void cuda_use_device_uuid(const std::string& uuid) {
    if (!cuda::use_device_uuid(uuid))
        throw Error(
            "the CUDA runtime has no device with the chosen GPU's UUID " + uuid +
            " (CUDA_VISIBLE_DEVICES may hide it): train with --backend cpu or choose another --device");
}

std::unique_ptr<CudaTrainerBackend> make_cuda_backend_ex(const TrainingAsset& asset, const NeuralConfig& config,
                                                         const neural::AdamConfig& adam,
                                                         const CudaBackendOptions& options, uint64_t seed) {
    if (!cuda_backend_available()) throw Error("CUDA backend: no usable CUDA GPU was found");
    return std::make_unique<CudaBackend>(asset, config, adam, options, seed);
}

std::unique_ptr<TrainerBackend> make_cuda_backend(const TrainingAsset& asset, const NeuralConfig& config,
                                                  const neural::AdamConfig& adam, uint64_t seed, bool deterministic) {
    CudaBackendOptions options;
    options.deterministic = deterministic;
    return make_cuda_backend_ex(asset, config, adam, options, seed);
}

} // namespace nbvh
