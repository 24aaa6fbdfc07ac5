// Device memory, step orchestration, gradient reduction, the non-finite guard, Adam and the per-leaf
// statistics of the CUDA trainer (see cuda_core.h). One CUDA stream; the only host syncs of a step
// are the read-back of the guard flag, the loss partials and the per-leaf statistics at its end.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>

#include "trainer/cuda/cuda_core.h"
#include "trainer/cuda/device_common.cuh"
#include "engine/neural/shared/adam_update.h"

namespace nbvh::cuda {
namespace {

template <class T>
struct DevBuf {
    T* p = nullptr;
    size_t n = 0;
    DevBuf() = default;
    DevBuf(const DevBuf&) = delete;
    DevBuf& operator=(const DevBuf&) = delete;
    ~DevBuf() { if (p) cudaFree(p); }
    void alloc(size_t count) {
        if (count <= n && p) return;
        if (p) cudaFree(p);
        p = nullptr;
        n = 0;
        NBVH_CUDA_CHECK(cudaMalloc(&p, std::max<size_t>(count, 1) * sizeof(T)));
        n = count;
    }
    void upload(const T* src, size_t count) {
        alloc(count);
        if (count) NBVH_CUDA_CHECK(cudaMemcpy(p, src, count * sizeof(T), cudaMemcpyHostToDevice));
    }
    void upload(const std::vector<T>& v) { upload(v.data(), v.size()); }
    void zero_async(size_t count, cudaStream_t s) {
        if (count) NBVH_CUDA_CHECK(cudaMemsetAsync(p, 0, count * sizeof(T), s));
    }
};

constexpr int kStatsThreads = 256;

__global__ void k_to_half(const float* src, __half* dst, uint32_t n) {
    const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) dst[i] = __float2half_rn(src[i]);
}

// Per-leaf statistics (cuts[0]) and per-block partial sums of the loss terms (fixed reduction order).
__global__ void k_stats(DevBatch b, uint32_t* leaf_samples, unsigned long long* leaf_loss_fx, double* partials) {
    __shared__ double red[6][kStatsThreads];
    const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    double v[6] = {0, 0, 0, 0, 0, 0};
    if (i < b.n && b.leaf[i] >= 0) {
        for (int q = 0; q < 5; ++q) v[q] = b.loss[5 * size_t(i) + q];
        v[5] = b.target[8 * size_t(i)] > 0.5f ? 1.0 : 0.0;
        if (b.cut[i] == 0) {
            atomicAdd(&leaf_samples[b.leaf[i]], 1u);
            atomicAdd(&leaf_loss_fx[b.leaf[i]], (unsigned long long)__double2ll_rn(v[4] * 4294967296.0));
        }
    }
    for (int q = 0; q < 6; ++q) red[q][threadIdx.x] = v[q];
    __syncthreads();
    for (int s = kStatsThreads / 2; s > 0; s >>= 1) {
        if (int(threadIdx.x) < s)
            for (int q = 0; q < 6; ++q) red[q][threadIdx.x] += red[q][threadIdx.x + s];
        __syncthreads();
    }
    if (threadIdx.x == 0)
        for (int q = 0; q < 6; ++q) partials[blockIdx.x * 6 + q] = red[q][0];
}

// MLP gradient = sum of the per-block slices in block order (deterministic), checked for finiteness.
__global__ void k_reduce_mlp(const float* slices, int blocks, float* grad, uint32_t* flag) {
    const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= NB_MLP_WEIGHT_COUNT) return;
    float s = 0.0f;
    for (int k = 0; k < blocks; ++k) s += slices[size_t(k) * NB_MLP_WEIGHT_COUNT + i];
    grad[i] = s;
    if (!isfinite(s)) atomicOr(flag, NB_GUARD_GRADIENT);
}

// Grid gradient: converts the deterministic fixed-point sums, and checks finiteness either way.
__global__ void k_check_grid(float* grad, const unsigned long long* fx, uint32_t n, uint32_t* flag) {
    const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) return;
    float g;
    if (fx) {
        g = float(double((long long)fx[i]) * (1.0 / double(NB_CUDA_FIXED_SCALE)));
        grad[i] = g;
    } else {
        g = grad[i];
    }
    if (!isfinite(g)) atomicOr(flag, NB_GUARD_GRADIENT);
}

// tcnn Adam: nb_adam_update of engine/neural/shared/adam_update.h, the CPU's update (per-parameter step
// counters; sparse skip of zero grid grads) on the batch-mean gradient (summed gradient / (loss scale x
// trained samples)), then the fp16 copy. Does nothing when the guard flag is set or no sample was trained.
__global__ void k_adam(float* w, float* m, float* v, uint32_t* t, __half* wh, const float* grad, uint32_t n,
                       GpuAdamRule r, float scale_inv, const uint32_t* flag, const uint32_t* valid) {
    const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n || *flag != 0u || *valid == 0u) return;
    float wi = w[i], mi = m[i], vi = v[i];
    uint32_t ti = t[i];
    if (!nb_adam_update(wi, mi, vi, ti, grad[i] * (scale_inv / float(*valid)), r, nullptr, nullptr, 0u)) return;
    m[i] = mi;
    v[i] = vi;
    t[i] = ti;
    w[i] = wi;
    wh[i] = __float2half_rn(wi);
}

class CoreImpl final : public Core {
public:
    CoreImpl(const CoreAsset& a, const CoreConfig& c) : cfg_(c), scale_(c.loss_scale) {
        NBVH_CUDA_CHECK(cudaStreamCreate(&stream_));
        for (auto& e : ev_) NBVH_CUDA_CHECK(cudaEventCreate(&e));
        mlp_prepare();
        node_boxes_.upload(a.node_boxes);
        children_.alloc(a.node_children.size() / 2);
        NBVH_CUDA_CHECK(cudaMemcpy(children_.p, a.node_children.data(), a.node_children.size() * 4, cudaMemcpyHostToDevice));
        mesh_nodes_.upload(a.mesh_nodes);
        tri_v_.upload(a.tri_vertices);
        tri_n_.upload(a.tri_normals);
        tri_a_.upload(a.tri_albedo);
        tri_uv_.upload(a.tri_uv);
        tri_tex_.upload(a.tri_texture);
        texels_.upload(a.texels.empty() ? std::vector<uint32_t>{0u} : a.texels);
        tex_info_.upload(a.texture_info.empty() ? std::vector<uint32_t>{0u, 1u, 1u} : a.texture_info);
        srgb_.upload(a.srgb_table.data(), a.srgb_table.size());
        tri_g_.upload(a.tri_geo_normal);
        da_.node_boxes = node_boxes_.p;
        da_.children = children_.p;
        da_.base_nodes = uint32_t(a.node_boxes.size() / 6);
        da_.mesh_nodes = a.mesh_nodes.empty() ? nullptr : mesh_nodes_.p;
        da_.tri_v = tri_v_.p; da_.tri_n = tri_n_.p; da_.tri_a = tri_a_.p; da_.tri_g = tri_g_.p;
        da_.tri_uv = tri_uv_.p; da_.tri_tex = tri_tex_.p; da_.texels = texels_.p; da_.tex_info = tex_info_.p;
        da_.srgb = srgb_.p;
        da_.enc = a.encoding;
        NBVH_CHECK_SIZE(!a.part_roots.empty() && a.part_boxes.size() == 6 * a.part_roots.size());
        part_boxes_.upload(a.part_boxes);
        part_roots_.upload(a.part_roots);
        da_.part_boxes = part_boxes_.p;
        da_.part_roots = part_roots_.p;
        da_.parts = uint32_t(a.part_roots.size());
        da_.min_exit = a.min_exit;

        NBVH_CHECK_SIZE(c.levels.size() == NB_GRID_MAX_LEVELS && c.mlp.size() == NB_MLP_WEIGHT_COUNT);
        for (uint32_t l = 0; l < NB_GRID_MAX_LEVELS; ++l) net_.levels[l] = c.levels[l];
        grid_n_ = uint32_t(c.grid.size());
        grid_w_.upload(c.grid);
        mlp_w_.upload(c.mlp);
        for (auto* b : {&grid_m_, &grid_v_}) { b->alloc(grid_n_); b->zero_async(grid_n_, stream_); }
        for (auto* b : {&mlp_m_, &mlp_v_}) { b->alloc(NB_MLP_WEIGHT_COUNT); b->zero_async(NB_MLP_WEIGHT_COUNT, stream_); }
        grid_t_.alloc(grid_n_); grid_t_.zero_async(grid_n_, stream_);
        mlp_t_.alloc(NB_MLP_WEIGHT_COUNT); mlp_t_.zero_async(NB_MLP_WEIGHT_COUNT, stream_);
        grid_h_.alloc(grid_n_);
        mlp_h_.alloc(NB_MLP_WEIGHT_COUNT);
        k_to_half<<<(grid_n_ + 255) / 256, 256, 0, stream_>>>(grid_w_.p, grid_h_.p, grid_n_);
        k_to_half<<<(NB_MLP_WEIGHT_COUNT + 255) / 256, 256, 0, stream_>>>(mlp_w_.p, mlp_h_.p, NB_MLP_WEIGHT_COUNT);
        NBVH_CUDA_CHECK(cudaGetLastError());
        grid_grad_.alloc(grid_n_);
        if (c.deterministic) { grid_grad_fx_.alloc(grid_n_); grid_grad_fx_.zero_async(grid_n_, stream_); }
        mlp_grad_.alloc(NB_MLP_WEIGHT_COUNT);
        net_.grid_h = grid_h_.p;
        net_.mlp_h = mlp_h_.p;
        net_.grid_grad = grid_grad_.p;
        net_.grid_grad_fx = c.deterministic ? grid_grad_fx_.p : nullptr;
        net_.grid_values = grid_n_;
        scalars_.alloc(4);
        NBVH_CUDA_CHECK(cudaStreamSynchronize(stream_));
    }
    ~CoreImpl() override {
        cudaStreamSynchronize(stream_);
        for (auto& e : ev_) cudaEventDestroy(e);
        cudaStreamDestroy(stream_);
    }

    void set_cuts(const std::vector<CoreCut>& cuts) override {
        NBVH_CHECK_SIZE(!cuts.empty() && cuts.size() <= NB_CUDA_MAX_CUTS);
        cuts_.clear();
        for (size_t k = 0; k < cuts.size(); ++k) {
            cuts_.push_back(std::make_unique<DevBuf<int32_t>>());
            cuts_.back()->upload(cuts[k].leaf_of_base_node);
        }
        leaves_ = cuts[0].leaves;
        leaf_draws_.alloc(leaves_);
        leaf_samples_.alloc(leaves_);
        leaf_loss_fx_.alloc(leaves_);
        keep_.alloc(leaves_);
    }

    void step(const CoreStepIn& in, CoreStepOut& out) override {
        NBVH_CHECK_SIZE(!cuts_.empty() && in.keep_probability && in.keep_probability->size() == leaves_);
        const uint32_t n = in.batch;
        ensure_batch(n);
        cudaStream_t s = stream_;
        // Scalars: [0..1] draws (u64), [2] valid samples, [3] guard flag.
        scalars_.zero_async(4, s);
        unsigned long long* draws = reinterpret_cast<unsigned long long*>(scalars_.p);
        uint32_t* valid = reinterpret_cast<uint32_t*>(scalars_.p) + 2;
        uint32_t* flag = reinterpret_cast<uint32_t*>(scalars_.p) + 3;
        leaf_draws_.zero_async(leaves_, s);
        leaf_samples_.zero_async(leaves_, s);
        leaf_loss_fx_.zero_async(leaves_, s);
        NBVH_CUDA_CHECK(cudaMemcpyAsync(keep_.p, in.keep_probability->data(), leaves_ * 4, cudaMemcpyHostToDevice, s));
        if (cfg_.deterministic) grid_grad_fx_.zero_async(grid_n_, s);
        else grid_grad_.zero_async(grid_n_, s);
        const int blocks = mlp_blocks_for(n);
        slices_.alloc(size_t(blocks) * NB_MLP_WEIGHT_COUNT);
        slices_.zero_async(size_t(blocks) * NB_MLP_WEIGHT_COUNT, s);

        DevCuts dc{};
        dc.count = uint32_t(cuts_.size());
        for (size_t k = 0; k < cuts_.size(); ++k) dc.leaf_of[k] = cuts_[k]->p;
        dc.keep = keep_.p;
        dc.leaf_draws = leaf_draws_.p;

        record(0);
        launch_sample(da_, dc, batch_, n, in.seed, in.step, draws, valid, s);
        record(1);
        launch_ground_truth(da_, batch_, s);
        record(2);
        launch_encode(net_, batch_, s);
        record(3);
        const LossParams lp{cfg_.loss, scale_};
        launch_mlp(net_, batch_, lp, slices_.p, blocks, flag, s);
        record(4);
        launch_grid_backward(net_, batch_, cfg_.deterministic, flag, s);
        record(5);
        const int sblocks = int((n + kStatsThreads - 1) / kStatsThreads);
        partials_.alloc(size_t(sblocks) * 6);
        k_stats<<<sblocks, kStatsThreads, 0, s>>>(batch_, leaf_samples_.p, leaf_loss_fx_.p, partials_.p);
        k_reduce_mlp<<<(NB_MLP_WEIGHT_COUNT + 255) / 256, 256, 0, s>>>(slices_.p, blocks, mlp_grad_.p, flag);
        k_check_grid<<<(grid_n_ + 255) / 256, 256, 0, s>>>(grid_grad_.p, cfg_.deterministic ? grid_grad_fx_.p : nullptr,
                                                             grid_n_, flag);
        const GpuAdamRule mlp_rule{in.learning_rate, cfg_.beta1, cfg_.beta2, cfg_.epsilon, cfg_.l2_reg, 0u};
        const GpuAdamRule grid_rule{in.learning_rate, cfg_.beta1, cfg_.beta2, cfg_.epsilon, cfg_.non_matrix_l2_reg,
                                    cfg_.skip_zero_grad_non_matrix ? 1u : 0u};
        k_adam<<<(NB_MLP_WEIGHT_COUNT + 255) / 256, 256, 0, s>>>(mlp_w_.p, mlp_m_.p, mlp_v_.p, mlp_t_.p, mlp_h_.p,
                                                                  mlp_grad_.p, NB_MLP_WEIGHT_COUNT, mlp_rule,
                                                                  1.0f / scale_, flag, valid);
        k_adam<<<(grid_n_ + 255) / 256, 256, 0, s>>>(grid_w_.p, grid_m_.p, grid_v_.p, grid_t_.p, grid_h_.p,
                                                      grid_grad_.p, grid_n_, grid_rule, 1.0f / scale_, flag, valid);
        NBVH_CUDA_CHECK(cudaGetLastError());
        record(6);

        // Read back (one sync).
        uint32_t sc[4];
        std::vector<double> part(size_t(sblocks) * 6);
        std::vector<unsigned long long> lfx(leaves_);
        out.leaf_draws.resize(leaves_);
        out.leaf_samples.resize(leaves_);
        NBVH_CUDA_CHECK(cudaMemcpyAsync(sc, scalars_.p, 16, cudaMemcpyDeviceToHost, s));
        NBVH_CUDA_CHECK(cudaMemcpyAsync(part.data(), partials_.p, part.size() * 8, cudaMemcpyDeviceToHost, s));
        NBVH_CUDA_CHECK(cudaMemcpyAsync(lfx.data(), leaf_loss_fx_.p, leaves_ * 8, cudaMemcpyDeviceToHost, s));
        NBVH_CUDA_CHECK(cudaMemcpyAsync(out.leaf_draws.data(), leaf_draws_.p, leaves_ * 4, cudaMemcpyDeviceToHost, s));
        NBVH_CUDA_CHECK(cudaMemcpyAsync(out.leaf_samples.data(), leaf_samples_.p, leaves_ * 4, cudaMemcpyDeviceToHost, s));
        NBVH_CUDA_CHECK(cudaStreamSynchronize(s));
        unsigned long long d64;
        std::memcpy(&d64, sc, 8);
        out.draws = d64;
        out.samples = sc[2];
        const uint32_t f = sc[3];
        double tot[6] = {0, 0, 0, 0, 0, 0};
        for (int b = 0; b < sblocks; ++b)
            for (int q = 0; q < 6; ++q) tot[q] += part[size_t(b) * 6 + q];
        out.vis = tot[0]; out.depth = tot[1]; out.normal = tot[2]; out.albedo = tot[3]; out.total = tot[4];
        out.hits = uint32_t(tot[5] + 0.5);
        out.leaf_loss.resize(leaves_);
        for (uint32_t i = 0; i < leaves_; ++i) out.leaf_loss[i] = double((long long)lfx[i]) / 4294967296.0;
        out.skipped = false;
        out.reason.clear();
        last_valid_ = out.samples;
        last_scale_ = scale_;
        if (out.samples == 0) {
            out.skipped = true;
            out.reason = "no training ray met a leaf of the cut";
        } else if (f & NB_GUARD_OUTPUT) {
            out.skipped = true;
            out.reason = "non-finite network output or loss";
        } else if (f & NB_GUARD_GRADIENT) {
            out.skipped = true;
            out.reason = "non-finite gradient (loss scale " + std::to_string(int(scale_)) + ", halved)";
            scale_ = std::max(1.0f, scale_ * 0.5f);
            good_steps_ = 0;
        } else if (scale_ < cfg_.loss_scale && ++good_steps_ >= 1000) {
            scale_ *= 2.0f; // grow back towards the configured scale after a quiet stretch
            good_steps_ = 0;
        }
        if (timing_) {
            float* tm[6] = {&tm_.sample_ms, &tm_.truth_ms, &tm_.encode_ms, &tm_.mlp_ms, &tm_.grid_bwd_ms, &tm_.adam_ms};
            for (int k = 0; k < 6; ++k) NBVH_CUDA_CHECK(cudaEventElapsedTime(tm[k], ev_[k], ev_[k + 1]));
        }
    }

    void read_weights(std::vector<float>& mlp, std::vector<float>& grid) const override {
        mlp.resize(NB_MLP_WEIGHT_COUNT);
        grid.resize(grid_n_);
        NBVH_CUDA_CHECK(cudaMemcpy(mlp.data(), mlp_w_.p, mlp.size() * 4, cudaMemcpyDeviceToHost));
        NBVH_CUDA_CHECK(cudaMemcpy(grid.data(), grid_w_.p, grid.size() * 4, cudaMemcpyDeviceToHost));
    }

    void read_last(std::vector<CoreSample>& samples, std::vector<float>& mlp_grad,
                   std::vector<float>& grid_grad) const override {
        const uint32_t n = batch_.n;
        std::vector<float> o(3 * n), d(3 * n), len(n), tg(8 * n);
        std::vector<int32_t> leaf(n);
        std::vector<uint32_t> cut(n);
        NBVH_CUDA_CHECK(cudaMemcpy(o.data(), batch_.origin, o.size() * 4, cudaMemcpyDeviceToHost));
        NBVH_CUDA_CHECK(cudaMemcpy(d.data(), batch_.dir, d.size() * 4, cudaMemcpyDeviceToHost));
        NBVH_CUDA_CHECK(cudaMemcpy(len.data(), batch_.length, len.size() * 4, cudaMemcpyDeviceToHost));
        NBVH_CUDA_CHECK(cudaMemcpy(tg.data(), batch_.target, tg.size() * 4, cudaMemcpyDeviceToHost));
        NBVH_CUDA_CHECK(cudaMemcpy(leaf.data(), batch_.leaf, leaf.size() * 4, cudaMemcpyDeviceToHost));
        NBVH_CUDA_CHECK(cudaMemcpy(cut.data(), batch_.cut, cut.size() * 4, cudaMemcpyDeviceToHost));
        samples.resize(n);
        for (uint32_t i = 0; i < n; ++i) {
            CoreSample& cs = samples[i];
            for (int k = 0; k < 3; ++k) { cs.origin[k] = o[3 * i + k]; cs.dir[k] = d[3 * i + k]; }
            cs.length = len[i];
            cs.leaf = leaf[i];
            cs.cut = cut[i];
            for (int k = 0; k < 8; ++k) cs.target[k] = tg[8 * i + k];
        }
        mlp_grad.resize(NB_MLP_WEIGHT_COUNT);
        grid_grad.resize(grid_n_);
        NBVH_CUDA_CHECK(cudaMemcpy(mlp_grad.data(), mlp_grad_.p, mlp_grad.size() * 4, cudaMemcpyDeviceToHost));
        NBVH_CUDA_CHECK(cudaMemcpy(grid_grad.data(), grid_grad_.p, grid_grad.size() * 4, cudaMemcpyDeviceToHost));
        const float inv = last_valid_ ? 1.0f / (last_scale_ * float(last_valid_)) : 0.0f;
        for (float& g : mlp_grad) g *= inv;
        for (float& g : grid_grad) g *= inv;
    }

    float loss_scale() const override { return scale_; }
    void set_timing(bool on) override { timing_ = on; }
    CoreTimings timings() const override { return tm_; }

private:
    static void NBVH_CHECK_SIZE(bool ok) {
        if (!ok) throw std::runtime_error("CUDA trainer: inconsistent sizes");
    }
    void record(int k) {
        if (timing_) NBVH_CUDA_CHECK(cudaEventRecord(ev_[k], stream_));
    }
    void ensure_batch(uint32_t n) {
        b_origin_.alloc(3 * size_t(n)); b_dir_.alloc(3 * size_t(n)); b_len_.alloc(n);
        b_leaf_.alloc(n); b_cut_.alloc(n); b_target_.alloc(8 * size_t(n)); b_points_.alloc(9 * size_t(n));
        b_feat_.alloc(size_t(n) * NB_MLP_INPUTS); b_dfeat_.alloc(size_t(n) * NB_MLP_INPUTS); b_loss_.alloc(5 * size_t(n));
        batch_ = DevBatch{b_origin_.p, b_dir_.p, b_len_.p, b_leaf_.p, b_cut_.p, b_target_.p, b_points_.p,
                          b_feat_.p, b_dfeat_.p, b_loss_.p, n};
    }

    CoreConfig cfg_;
    float scale_ = 128.0f, last_scale_ = 128.0f;
    uint32_t good_steps_ = 0, last_valid_ = 0;
    cudaStream_t stream_{};
    cudaEvent_t ev_[7]{};
    bool timing_ = false;
    CoreTimings tm_;
    DevAsset da_{};
    DevNetwork net_{};
    DevBatch batch_{};
    uint32_t grid_n_ = 0, leaves_ = 0;
    DevBuf<float> node_boxes_, tri_v_, tri_n_, tri_a_, tri_g_, part_boxes_, tri_uv_, srgb_;
    DevBuf<uint32_t> part_roots_, texels_, tex_info_;
    DevBuf<int32_t> tri_tex_;
    DevBuf<uint2> children_;
    DevBuf<GpuBvhNode> mesh_nodes_;
    DevBuf<float> grid_w_, grid_m_, grid_v_, grid_grad_, mlp_w_, mlp_m_, mlp_v_, mlp_grad_, slices_, keep_;
    DevBuf<uint32_t> grid_t_, mlp_t_, leaf_draws_, leaf_samples_, scalars_;
    DevBuf<__half> grid_h_, mlp_h_, b_feat_;
    DevBuf<unsigned long long> grid_grad_fx_, leaf_loss_fx_;
    DevBuf<double> partials_;
    std::vector<std::unique_ptr<DevBuf<int32_t>>> cuts_;
    DevBuf<float> b_origin_, b_dir_, b_len_, b_target_, b_points_, b_dfeat_, b_loss_;
    DevBuf<int32_t> b_leaf_;
    DevBuf<uint32_t> b_cut_;
};

} // namespace

bool device_available(std::string* name) {
    int count = 0;
    if (cudaGetDeviceCount(&count) != cudaSuccess || count <= 0) {
        cudaGetLastError(); // clear the sticky "no device" error
        return false;
    }
    cudaDeviceProp prop{};
    if (cudaGetDeviceProperties(&prop, 0) != cudaSuccess) return false;
    if (prop.major < 7) return false; // tensor-core WMMA fp16 needs sm_70+
    if (name) *name = prop.name;
    return true;
}

std::unique_ptr<Core> make_core(const CoreAsset& asset, const CoreConfig& config) {
    return std::make_unique<CoreImpl>(asset, config);
}

} // namespace nbvh::cuda
