// Device memory and step orchestration of the CUDA trainer (see cuda_core.h; the kernels:
// sampling_kernels.cu, network_kernels.cu, update_kernels.cu). The network part runs on one stream; the next
// step's batch (sampling + ground truth) is drawn ahead on a second stream while it runs (prefetch,
// see CoreConfig::prefetch). The only host syncs of a step are the read-back of the guard flag, the
// loss partials and the per-leaf statistics at its end.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>

#include "engine/core/log.h"
#include "trainer/cuda/cuda_core.h"
#include "trainer/cuda/device_common.cuh"
#include "trainer/cuda/update_kernels.cuh"

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

// One batch of training samples (sampling + ground truth output) with the per-draw counters of its
// sampling pass. Two slots: the step trains one while the next step's batch is drawn into the other.
struct BatchSlot {
    DevBuf<float> origin, dir, len, target, points, keep;
    DevBuf<int32_t> leaf;
    DevBuf<uint32_t> cut, leaf_draws, scalars; // scalars: [0..1] draws (u64), [2] valid samples
    float* keep_host = nullptr;                // pinned staging of the keep probabilities it was drawn with
    size_t keep_host_n = 0;
    cudaEvent_t sampled{};                     // recorded after its sampling (rays, segment points)
    cudaEvent_t ready{};                       // recorded after its ground truth
    DevBatch batch{};
    // What it holds (a prefetched batch is used only when all of these match the step).
    bool filled = false;
    uint32_t step = 0, n = 0;
    uint64_t seed = 0, cut_gen = 0;

    BatchSlot() = default;
    BatchSlot(const BatchSlot&) = delete;
    BatchSlot& operator=(const BatchSlot&) = delete;
    ~BatchSlot() {
        if (keep_host) cudaFreeHost(keep_host);
        if (sampled) cudaEventDestroy(sampled);
        if (ready) cudaEventDestroy(ready);
    }
    unsigned long long* draws() { return reinterpret_cast<unsigned long long*>(scalars.p); }
    uint32_t* valid() { return scalars.p + 2; }
};

class CoreImpl final : public Core {
public:
    CoreImpl(const CoreAsset& a, const CoreConfig& c) : cfg_(c), scale_(c.loss_scale) {
        NBVH_CUDA_CHECK(cudaStreamCreate(&stream_));
        NBVH_CUDA_CHECK(cudaStreamCreateWithFlags(&side_, cudaStreamNonBlocking));
        for (auto& e : ev_) NBVH_CUDA_CHECK(cudaEventCreate(&e));
        NBVH_CUDA_CHECK(cudaEventCreateWithFlags(&mlp_done_, cudaEventDisableTiming));
        for (BatchSlot& b : slots_) {
            NBVH_CUDA_CHECK(cudaEventCreateWithFlags(&b.sampled, cudaEventDisableTiming));
            NBVH_CUDA_CHECK(cudaEventCreateWithFlags(&b.ready, cudaEventDisableTiming));
            b.scalars.alloc(4);
        }
        mlp_prepare();
        // The base BVH stays on the host: each cut's compact tree is built from it (set_cuts).
        base_boxes_ = a.node_boxes;
        base_children_ = a.node_children;
        part_roots_ = a.part_roots;
        mesh_wide_.upload(a.mesh_wide);
        tri_v_.upload(a.tri_vertices);
        tri_n_.upload(a.tri_normals);
        tri_a_.upload(a.tri_albedo);
        tri_uv_.upload(a.tri_uv);
        tri_tex_.upload(a.tri_texture);
        texels_.upload(a.texels.empty() ? std::vector<uint32_t>{0u} : a.texels);
        tex_info_.upload(a.texture_info.empty() ? std::vector<uint32_t>{0u, 1u, 1u} : a.texture_info);
        srgb_.upload(a.srgb_table.data(), a.srgb_table.size());
        tri_g_.upload(a.tri_geo_normal);
        if (!a.tri_coverage.empty()) {
            coverage_.upload(a.tri_coverage);
            da_.coverage = coverage_.p;
        }
        if (!a.tri_normal_map.empty()) {
            normal_maps_.upload(a.tri_normal_map);
            da_.normal_maps = normal_maps_.p;
        }
        da_.mesh_wide = a.mesh_wide.empty() ? nullptr : mesh_wide_.p;
        da_.tri_v = tri_v_.p; da_.tri_n = tri_n_.p; da_.tri_a = tri_a_.p; da_.tri_g = tri_g_.p;
        da_.tri_uv = tri_uv_.p; da_.tri_tex = tri_tex_.p; da_.texels = texels_.p; da_.tex_info = tex_info_.p;
        da_.srgb = srgb_.p;
        da_.enc = a.encoding;
        NBVH_CHECK_SIZE(!a.part_roots.empty() && a.part_boxes.size() == 6 * a.part_roots.size());
        part_boxes_.upload(a.part_boxes);
        da_.part_boxes = part_boxes_.p;
        da_.parts = uint32_t(a.part_roots.size());
        da_.min_exit = a.min_exit;

        NBVH_CHECK_SIZE(c.levels.size() == NB_GRID_MAX_LEVELS && c.mlp.size() == NB_MLP_WEIGHT_COUNT);
        for (uint32_t l = 0; l < NB_GRID_MAX_LEVELS; ++l) {
            net_.levels[l] = c.levels[l];
            // k_encode reads entry pairs (2e, 2e + 1) as one 16-byte word, the fine grid backward adds to
            // them with one reduction: even offsets and sizes keep every pair inside its level's table.
            NBVH_CHECK_SIZE(c.levels[l].offset % 2u == 0u && c.levels[l].size % 2u == 0u);
        }
        grid_n_ = uint32_t(c.grid.size());
        NBVH_CHECK_SIZE(grid_n_ % 8u == 0u); // whole entry pairs (8 values each)
        grid_w_.upload(c.grid);
        mlp_w_.upload(c.mlp);
        for (auto* b : {&grid_m_, &grid_v_}) { b->alloc(grid_n_); b->zero_async(grid_n_, stream_); }
        for (auto* b : {&mlp_m_, &mlp_v_}) { b->alloc(NB_MLP_WEIGHT_COUNT); b->zero_async(NB_MLP_WEIGHT_COUNT, stream_); }
        grid_t_.alloc(grid_n_); grid_t_.zero_async(grid_n_, stream_);
        mlp_t_.alloc(NB_MLP_WEIGHT_COUNT); mlp_t_.zero_async(NB_MLP_WEIGHT_COUNT, stream_);
        grid_h_.alloc(grid_n_);
        mlp_h_.alloc(NB_MLP_WEIGHT_COUNT);
        launch_to_half(grid_w_.p, grid_h_.p, grid_n_, stream_);
        launch_to_half(mlp_w_.p, mlp_h_.p, NB_MLP_WEIGHT_COUNT, stream_);
        NBVH_CUDA_CHECK(cudaGetLastError());
        if (c.deterministic) { grid_grad_fx_.alloc(grid_n_); grid_grad_fx_.zero_async(grid_n_, stream_); }
        mlp_grad_.alloc(NB_MLP_WEIGHT_COUNT);
        net_.grid_h = grid_h_.p;
        net_.mlp_h = mlp_h_.p;
        split_ = coarse_split(net_, c.deterministic);
        // k_reduce_check reads the fp16 gradient 8 values at a time from split_.values, k_adam 4 at a time:
        // level offsets and sizes are even, so (offset + size) x 4 features is a multiple of 8.
        NBVH_CHECK_SIZE(split_.values % 8u == 0u);
        // fp32 gradient: every value in the deterministic mode, the coarse levels' in the fast mode (whose
        // fine levels' gradient is fp16, indexed like the grid).
        grid_grad_.alloc(grid_split());
        net_.grid_grad = grid_grad_.p;
        if (!c.deterministic) grid_grad_h_.alloc(grid_n_);
        net_.grid_grad_h = c.deterministic ? nullptr : grid_grad_h_.p;
        net_.grid_grad_fx = c.deterministic ? grid_grad_fx_.p : nullptr;
        net_.grid_values = grid_n_;
        flag_.alloc(1);
        bias_sqrt_.alloc(kAdamBiasTable);
        bias_div_.alloc(kAdamBiasTable);
        launch_adam_bias_tables(c.beta1, c.beta2, bias_sqrt_.p, bias_div_.p, stream_);
        NBVH_CUDA_CHECK(cudaStreamSynchronize(stream_));
    }
    ~CoreImpl() override {
        cudaStreamSynchronize(side_);
        cudaStreamSynchronize(stream_);
        for (auto& e : ev_) cudaEventDestroy(e);
        cudaEventDestroy(mlp_done_);
        cudaStreamDestroy(side_);
        cudaStreamDestroy(stream_);
    }

    void set_cuts(const std::vector<CoreCut>& cuts) override {
        NBVH_CHECK_SIZE(!cuts.empty() && cuts.size() <= NB_CUDA_MAX_CUTS);
        // A batch drawn ahead on the old cuts is dropped (its leaf slots name the old cut's leaves); its
        // sampling may still read the buffers freed below.
        NBVH_CUDA_CHECK(cudaStreamSynchronize(side_));
        cut_gen_++;
        std::vector<CutNode> nodes;
        std::vector<uint32_t> roots;
        for (const CoreCut& c : cuts)
            append_cut_tree(base_boxes_, base_children_, c.leaf_of_base_node, part_roots_, nodes, roots);
        cut_nodes_.upload(nodes);
        cut_roots_.upload(roots);
        cut_count_ = uint32_t(cuts.size());
        leaves_ = cuts[0].leaves;
        leaf_samples_.alloc(size_t(leaves_) * kLeafCopies);
        leaf_loss_fx_.alloc(size_t(leaves_) * kLeafCopies);
    }

    void step(const CoreStepIn& in, CoreStepOut& out) override {
        NBVH_CHECK_SIZE(cut_count_ > 0 && in.keep_probability && in.keep_probability->size() == leaves_);
        const uint32_t n = in.batch;
        ensure_network_batch(n);
        cudaStream_t s = stream_;
        // This step's batch: the one drawn ahead by the previous step when it matches (same step, size,
        // seed and cuts; drawn with the previous step's keep probabilities), else drawn now.
        int cur = -1;
        for (int k = 0; k < 2; ++k) {
            const BatchSlot& b = slots_[k];
            if (b.filled && b.step == in.step && b.n == n && b.seed == in.seed && b.cut_gen == cut_gen_) cur = k;
        }
        const bool prefetched = cur >= 0 && !timing_;
        if (prefetched) {
            NBVH_CUDA_CHECK(cudaStreamWaitEvent(s, slots_[cur].sampled, 0));
        } else {
            NBVH_CUDA_CHECK(cudaStreamSynchronize(side_)); // a mismatching batch in flight may use slot 0
            cur = 0;
            draw_batch(slots_[cur], in.step, n, in.seed, *in.keep_probability, s);
        }
        for (BatchSlot& b : slots_) b.filled = false;
        BatchSlot& slot = slots_[cur];
        DevBatch batch = slot.batch;
        batch.features = b_feat_.p;
        batch.dfeatures = b_dfeat_.p;
        batch.loss = b_loss_.p;
        last_slot_ = cur;
        uint32_t* valid = slot.valid();
        uint32_t* flag = flag_.p;
        flag_.zero_async(1, s);
        leaf_samples_.zero_async(size_t(leaves_) * kLeafCopies, s);
        leaf_loss_fx_.zero_async(size_t(leaves_) * kLeafCopies, s);
        if (cfg_.deterministic) {
            grid_grad_fx_.zero_async(grid_n_, s);
        } else {
            grid_grad_.zero_async(split_.values, s);
            grid_grad_h_.zero_async(grid_n_, s);
        }
        const int blocks = mlp_blocks_for(n);
        slices_.alloc(size_t(blocks) * NB_MLP_WEIGHT_COUNT); // k_mlp writes every value of its block's slice

        launch_encode(net_, batch, s);
        // A batch drawn ahead: the encode needs its rays and points, the fused MLP its targets as well,
        // so the encode runs beside that batch's ground truth.
        if (prefetched) NBVH_CUDA_CHECK(cudaStreamWaitEvent(s, slot.ready, 0));
        record(3);
        const LossParams lp{cfg_.loss, scale_};
        launch_mlp(net_, batch, lp, slices_.p, blocks, flag, s);
        record(4);
        // The next step's batch, drawn while this step's grid backward and Adam run (not when timing the
        // phases): the sampler is bound by its lanes' instructions, the grid backward by L2 reductions,
        // while the fused MLP holds every SM's registers, so a draw issued at the step's start only took
        // turns with it. H200: paper-size training 21.5 / 20.9 -> 19.4 / 19.5 s in one call; the
        // fixed-cut step benchmark did not move (results/cuda_training.md).
        if (cfg_.prefetch && !timing_) {
            NBVH_CUDA_CHECK(cudaEventRecord(mlp_done_, s));
            NBVH_CUDA_CHECK(cudaStreamWaitEvent(side_, mlp_done_, 0));
            BatchSlot& next = slots_[1 - cur];
            draw_batch(next, in.step + 1, n, in.seed, *in.keep_probability, side_);
            next.filled = true;
        }
        launch_grid_backward(net_, batch, cfg_.deterministic, flag, s);
        record(5);
        const int sblocks = stats_blocks(n);
        partials_.alloc(size_t(sblocks) * 6);
        launch_stats(batch, leaves_, leaf_samples_.p, leaf_loss_fx_.p, partials_.p, s);
        // The deterministic sums are converted (and checked) by k_check_grid. In the fast mode the coarse
        // levels' fp32 sums need no pass: both grid backward kernels raise the guard on a non-finite
        // dL/dfeature, k_grid_backward_coarse on a block's fp16 partial that overflowed, and the fp32 sum of
        // finite partials cannot overflow (each dL/dfeature is a 64-term fp32 sum of fp16 x fp16 products,
        // k_mlp's wmma, |x| <= 64 x 65504^2 = 2.7e11, and an entry takes at most 24 weighted (w <= 1) adds
        // per sample: below FLT_MAX for any batch below 5e25); the fine levels' fp16 sums can overflow and
        // are checked by k_reduce_check, which also sums the MLP gradient's slices.
        launch_reduce_check(slices_.p, blocks, mlp_grad_.p, grid_grad_h_.p, split_.values,
                            cfg_.deterministic ? split_.values : grid_n_, flag, s);
        if (cfg_.deterministic) launch_check_grid(grid_grad_.p, grid_grad_fx_.p, grid_n_, flag, s);
        const GpuAdamRule mlp_rule{in.learning_rate, cfg_.beta1, cfg_.beta2, cfg_.epsilon, cfg_.l2_reg, 0u};
        const GpuAdamRule grid_rule{in.learning_rate, cfg_.beta1, cfg_.beta2, cfg_.epsilon, cfg_.non_matrix_l2_reg,
                                    cfg_.skip_zero_grad_non_matrix ? 1u : 0u};
        const AdamGroup mlp{mlp_w_.p,
                            mlp_m_.p,
                            mlp_v_.p,
                            mlp_t_.p,
                            mlp_h_.p,
                            mlp_grad_.p,
                            nullptr,
                            NB_MLP_WEIGHT_COUNT,
                            NB_MLP_WEIGHT_COUNT,
                            mlp_rule};
        const AdamGroup grid{grid_w_.p,    grid_m_.p,      grid_v_.p,    grid_t_.p, grid_h_.p,
                             grid_grad_.p, grid_grad_h_.p, grid_split(), grid_n_,   grid_rule};
        launch_adam(mlp, grid, 1.0f / scale_, bias_sqrt_.p, bias_div_.p, flag, valid, s);
        record(6);

        // Read back (one sync).
        uint32_t sc[4];
        std::vector<double> part(size_t(sblocks) * 6);
        std::vector<unsigned long long> lfx(leaves_);
        out.leaf_draws.resize(leaves_);
        out.leaf_samples.resize(leaves_);
        NBVH_CUDA_CHECK(cudaMemcpyAsync(sc, slot.scalars.p, 12, cudaMemcpyDeviceToHost, s));
        NBVH_CUDA_CHECK(cudaMemcpyAsync(sc + 3, flag, 4, cudaMemcpyDeviceToHost, s));
        NBVH_CUDA_CHECK(cudaMemcpyAsync(part.data(), partials_.p, part.size() * 8, cudaMemcpyDeviceToHost, s));
        NBVH_CUDA_CHECK(cudaMemcpyAsync(lfx.data(), leaf_loss_fx_.p, leaves_ * 8, cudaMemcpyDeviceToHost, s));
        NBVH_CUDA_CHECK(cudaMemcpyAsync(out.leaf_draws.data(), slot.leaf_draws.p, leaves_ * 4, cudaMemcpyDeviceToHost, s));
        NBVH_CUDA_CHECK(cudaMemcpyAsync(out.leaf_samples.data(), leaf_samples_.p, leaves_ * 4, cudaMemcpyDeviceToHost, s));
        NBVH_CUDA_CHECK(cudaStreamSynchronize(s)); // not side_: the next batch goes on being drawn
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
    void read_half_weights(std::vector<uint16_t>& mlp, std::vector<uint16_t>& grid) const override {
        mlp.resize(NB_MLP_WEIGHT_COUNT);
        grid.resize(grid_n_);
        NBVH_CUDA_CHECK(cudaMemcpy(mlp.data(), mlp_h_.p, mlp.size() * 2, cudaMemcpyDeviceToHost));
        NBVH_CUDA_CHECK(cudaMemcpy(grid.data(), grid_h_.p, grid.size() * 2, cudaMemcpyDeviceToHost));
    }

    void read_last(std::vector<CoreSample>& samples, std::vector<float>& mlp_grad,
                   std::vector<float>& grid_grad) const override {
        const DevBatch& b = slots_[last_slot_].batch;
        const uint32_t n = b.n;
        std::vector<float> o(3 * n), d(3 * n), len(n), tg(8 * n);
        std::vector<int32_t> leaf(n);
        std::vector<uint32_t> cut(n);
        NBVH_CUDA_CHECK(cudaMemcpy(o.data(), b.origin, o.size() * 4, cudaMemcpyDeviceToHost));
        NBVH_CUDA_CHECK(cudaMemcpy(d.data(), b.dir, d.size() * 4, cudaMemcpyDeviceToHost));
        NBVH_CUDA_CHECK(cudaMemcpy(len.data(), b.length, len.size() * 4, cudaMemcpyDeviceToHost));
        NBVH_CUDA_CHECK(cudaMemcpy(tg.data(), b.target, tg.size() * 4, cudaMemcpyDeviceToHost));
        NBVH_CUDA_CHECK(cudaMemcpy(leaf.data(), b.leaf, leaf.size() * 4, cudaMemcpyDeviceToHost));
        NBVH_CUDA_CHECK(cudaMemcpy(cut.data(), b.cut, cut.size() * 4, cudaMemcpyDeviceToHost));
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
        NBVH_CUDA_CHECK(
            cudaMemcpy(grid_grad.data(), grid_grad_.p, size_t(grid_split()) * 4, cudaMemcpyDeviceToHost));
        if (grid_split() < grid_n_) { // the fast mode's fine levels: fp16
            std::vector<__half> h(grid_n_ - grid_split());
            NBVH_CUDA_CHECK(
                cudaMemcpy(h.data(), grid_grad_h_.p + grid_split(), h.size() * 2, cudaMemcpyDeviceToHost));
            for (size_t k = 0; k < h.size(); ++k) grid_grad[grid_split() + k] = __half2float(h[k]);
        }
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
    void ensure_network_batch(uint32_t n) {
        b_feat_.alloc(size_t(n) * NB_MLP_INPUTS); b_dfeat_.alloc(size_t(n) * NB_MLP_INPUTS); b_loss_.alloc(5 * size_t(n));
    }

    // Sampling (first-leaf search, roulette) and ground truth of `step` into `b`, on stream `st`, with
    // the given keep probabilities of cuts[0]; records b.sampled and b.ready.
    void draw_batch(BatchSlot& b, uint32_t step, uint32_t n, uint64_t seed, const std::vector<float>& keep,
                    cudaStream_t st) {
        b.origin.alloc(3 * size_t(n)); b.dir.alloc(3 * size_t(n)); b.len.alloc(n);
        b.leaf.alloc(n); b.cut.alloc(n); b.target.alloc(8 * size_t(n)); b.points.alloc(9 * size_t(n));
        b.batch = DevBatch{b.origin.p, b.dir.p, b.len.p, b.leaf.p, b.cut.p, b.target.p, b.points.p,
                           nullptr, nullptr, nullptr, n};
        b.keep.alloc(leaves_);
        b.leaf_draws.alloc(leaves_);
        if (b.keep_host_n < leaves_) {
            if (b.keep_host) NBVH_CUDA_CHECK(cudaFreeHost(b.keep_host));
            b.keep_host = nullptr;
            NBVH_CUDA_CHECK(cudaMallocHost(&b.keep_host, std::max<size_t>(leaves_, 1) * sizeof(float)));
            b.keep_host_n = leaves_;
        }
        // The slot's previous copy from keep_host is done: the slot was last drawn at least one
        // synchronised step ago, or on this stream.
        std::memcpy(b.keep_host, keep.data(), leaves_ * sizeof(float));
        NBVH_CUDA_CHECK(cudaMemcpyAsync(b.keep.p, b.keep_host, leaves_ * 4, cudaMemcpyHostToDevice, st));
        b.scalars.zero_async(4, st);
        b.leaf_draws.zero_async(leaves_, st);
        DevCuts dc{};
        dc.count = cut_count_;
        dc.nodes = cut_nodes_.p;
        dc.roots = cut_roots_.p;
        dc.keep = b.keep.p;
        dc.leaf_draws = b.leaf_draws.p;
        if (st == stream_) record(0);
        launch_sample(da_, dc, b.batch, n, seed, step, b.draws(), b.valid(), st);
        if (st == stream_) record(1);
        NBVH_CUDA_CHECK(cudaEventRecord(b.sampled, st));
        launch_ground_truth(da_, b.batch, seed, step, st);
        if (st == stream_) record(2);
        NBVH_CUDA_CHECK(cudaEventRecord(b.ready, st));
        b.step = step;
        b.n = n;
        b.seed = seed;
        b.cut_gen = cut_gen_;
    }

    CoreConfig cfg_;
    float scale_ = 128.0f, last_scale_ = 128.0f;
    uint32_t good_steps_ = 0, last_valid_ = 0;
    cudaStream_t stream_{}, side_{}; // network part; batches drawn ahead
    cudaEvent_t ev_[7]{};
    cudaEvent_t mlp_done_{}; // the next batch's draw waits for this step's fused MLP
    bool timing_ = false;
    CoreTimings tm_;
    DevAsset da_{};
    DevNetwork net_{};
    BatchSlot slots_[2];
    int last_slot_ = 0;
    uint64_t cut_gen_ = 0;
    uint32_t grid_n_ = 0, leaves_ = 0;
    std::vector<float> base_boxes_;                   // host: 6 per base node
    std::vector<uint32_t> base_children_, part_roots_; // host: 2 per base node; base root per part
    DevBuf<CutNode> cut_nodes_;                       // every cut's compact tree (cut_tree.h)
    DevBuf<uint32_t> cut_roots_;                      // [cut * parts + part]
    uint32_t cut_count_ = 0;
    DevBuf<float> tri_v_, tri_n_, tri_a_, tri_g_, part_boxes_, tri_uv_, srgb_;
    DevBuf<uint32_t> texels_, tex_info_;
    DevBuf<int32_t> tri_tex_;
    DevBuf<TriCoverage> coverage_;
    DevBuf<TriNormalMap> normal_maps_;
    DevBuf<GpuWideNode> mesh_wide_;
    DevBuf<float> grid_w_, grid_m_, grid_v_, grid_grad_, mlp_w_, mlp_m_, mlp_v_, mlp_grad_, slices_;
    DevBuf<uint32_t> grid_t_, mlp_t_, leaf_samples_, flag_;
    DevBuf<__half> grid_h_, mlp_h_, b_feat_;
    DevBuf<unsigned long long> grid_grad_fx_, leaf_loss_fx_;
    DevBuf<__half> grid_grad_h_; // the fast mode's fine-level gradient (fp16 vector reductions)
    CoarseSplit split_;          // the fast mode's coarse levels (fp32 gradient below split_.values)
    // Parameters below this index take the fp32 gradient (all in the deterministic mode).
    uint32_t grid_split() const { return cfg_.deterministic ? grid_n_ : split_.values; }
    DevBuf<double> partials_;
    DevBuf<float> bias_sqrt_, bias_div_; // Adam's bias-correction factors per step t (k_adam_bias_tables)
    DevBuf<float> b_dfeat_, b_loss_; // features (b_feat_ above), dL/dfeature and losses: network part only
};

} // namespace

bool device_available(std::string* name) {
    int count = 0;
    if (cudaGetDeviceCount(&count) != cudaSuccess || count <= 0) {
        cudaGetLastError(); // clear the sticky "no device" error
        return false;
    }
    int dev = 0; // this thread's current device (use_device_uuid may have chosen it)
    if (cudaGetDevice(&dev) != cudaSuccess) return false;
    cudaDeviceProp prop{};
    if (cudaGetDeviceProperties(&prop, dev) != cudaSuccess) return false;
    if (prop.major < 7) return false; // tensor-core WMMA fp16 needs sm_70+
    if (name) *name = prop.name;
    return true;
}

bool use_device_uuid(const std::string& uuid) {
    int count = 0;
    if (cudaGetDeviceCount(&count) != cudaSuccess) {
        cudaGetLastError();
        return false;
    }
    for (int d = 0; d < count; ++d) {
        cudaDeviceProp prop{};
        if (cudaGetDeviceProperties(&prop, d) != cudaSuccess) continue;
        static_assert(sizeof(prop.uuid.bytes) == 16);
        if (format_uuid(reinterpret_cast<const unsigned char*>(prop.uuid.bytes)) == uuid)
            return cudaSetDevice(d) == cudaSuccess;
    }
    return false;
}

std::unique_ptr<Core> make_core(const CoreAsset& asset, const CoreConfig& config) {
    return std::make_unique<CoreImpl>(asset, config);
}

} // namespace nbvh::cuda
