#include "trainer/cpu/cpu_backend.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <thread>

#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/neural/adam.h"
#include "engine/neural/batched_network.h"
#include "engine/neural/losses.h"
#include "shaders/shared/neural_query.h"
#include "trainer/ground_truth.h"

namespace nbvh {

TrainingSample draw_training_sample(const TrainingAsset& asset, std::span<const TrainingCut* const> cuts,
                                    const SampleSlot& where, uint32_t* leaf_draws, uint64_t& draws, uint32_t max_draws) {
    TrainingSample s;
    for (uint32_t attempt = 0; attempt < max_draws; ++attempt) {
        draws++;
        Pcg32 rng = where.attempt_rng(attempt);
        const uint32_t c = cuts.size() > 1 ? std::min(uint32_t(rng.next_float() * float(cuts.size())),
                                                     uint32_t(cuts.size() - 1))
                                           : 0u;
        // The part (one draw only with several, so one-asset ray sets are unchanged), then the origin
        // in its sampling box; the cut search stays inside its subtree.
        const TrainingPart& part = asset.parts[asset.parts.size() > 1 ? pick_part(asset, rng.next_float()) : 0u];
        const glm::vec3 lo = part.sampling_box.lo, ext = part.sampling_box.extent();
        const glm::vec3 o = lo + ext * glm::vec3(rng.next_float(), rng.next_float(), rng.next_float());
        const glm::vec3 d = uniform_sphere_direction(rng.next_float(), rng.next_float());
        const float dilation = 1e-5f + 1e-4f * rng.next_float(); // notes §1, training dilation
        const FirstLeaf f = first_leaf_of_cut(asset.bvh(), asset.node_boxes, *cuts[c], o, d, dilation, asset.min_exit,
                                              part.root);
        if (f.leaf < 0) continue; // the ray meets no leaf: redraw
        if (c == 0) {
            if (leaf_draws) leaf_draws[f.leaf]++;
            const float keep = cuts[0]->keep_probability[size_t(f.leaf)];
            if (keep < 1.0f && rng.next_float() >= keep) continue; // rejected: redraw (no stale replay)
        }
        // Move the origin to the segment start: training always uses the whole forward box segment
        // (notes §1), also when the origin is inside the leaf.
        s.origin = o + d * f.t_entry;
        s.dir = d;
        s.length = std::max(f.t_exit - f.t_entry, 0.0f);
        s.cut = c;
        s.leaf = f.leaf;
        return s;
    }
    return s;
}

namespace {

// fn(t) for t in [0, n) on n threads (t = 0 on the calling thread).
template <class F>
void run_on_threads(unsigned n, F&& fn) {
    if (n == 1) {
        fn(0u);
        return;
    }
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < n; ++t) pool.emplace_back([&fn, t] { fn(t); });
    fn(0u);
    for (std::thread& th : pool) th.join();
}

bool all_finite(const float* v, size_t n) {
    // Sum of (x * 0) is NaN iff some x is NaN or Inf; cheaper than a branch per value.
    float acc = 0.0f;
    for (size_t i = 0; i < n; ++i) acc += v[i] * 0.0f;
    return acc == 0.0f;
}

class CpuBackend final : public TrainerBackend {
public:
    CpuBackend(const TrainingAsset& asset, const NeuralConfig& config, const neural::AdamConfig& adam,
               const CpuBackendOptions& options, uint64_t seed)
        : asset_(asset), weights_(neural::create_network(config, seed)),
          adam_(adam, weights_.mlp.size(), weights_.grid.size()) {
        threads_ = options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
        per_thread_.resize(threads_);
        mlp_grad_.assign(weights_.mlp.size(), 0.0f);
        grid_grad_.assign(weights_.grid.size(), 0.0f);
        // A dense grid gradient per thread while the table is small (2^15 CPU default: ~0.8 M values);
        // bigger tables (2^18 paper default: 5.4 M values = 21 MiB per thread, cleared and reduced
        // every step) collect (index, grad) pairs instead (~0.8 M pairs per 1024 samples).
        dense_grid_ = weights_.grid.size() <= kDenseGridValues;
    }

    const char* name() const override { return "cpu"; }

    void read_weights(neural::NetworkWeights& out) const override { out = weights_; }

    StepStats step(const StepParams& params) override {
        NBVH_CHECK(!params.cuts.empty() && params.cuts[0] != nullptr);
        const uint32_t batch = params.batch_size;
        const size_t leaves = params.cuts[0]->size();
        const unsigned n_threads = std::min<unsigned>(threads_, std::max(1u, batch / 64u));

        auto work = [&](unsigned t) {
            ThreadState& ts = per_thread_[t];
            ts.reset(weights_, leaves, dense_grid_);
            if (!ts.tile) ts.tile = neural::make_batch_tile();
            neural::BatchTile& tile = *ts.tile;
            const neural::GridGradSink sink{dense_grid_ ? ts.grid_grad.data() : nullptr,
                                            dense_grid_ ? nullptr : &ts.grid_sparse};
            const uint32_t begin = uint32_t(uint64_t(batch) * t / n_threads);
            const uint32_t end = uint32_t(uint64_t(batch) * (t + 1) / n_threads);
            // Slots are drawn in order and trained in tiles of kBatchTile samples (batched network).
            std::array<neural::SegmentQuery, neural::kBatchTile> queries;
            std::array<TileSample, neural::kBatchTile> meta;
            for (uint32_t i = begin; i < end;) {
                uint32_t n = 0;
                for (; i < end && n < neural::kBatchTile; ++i) {
                    // Streams per (step, slot, attempt): reproducible whatever the thread count.
                    const TrainingSample s = draw_training_sample(asset_, params.cuts, {params.seed, params.step, i},
                                                                  ts.leaf_draws.data(), ts.draws);
                    if (s.leaf < 0) continue; // starved (no reachable leaf): counted as not trained
                    const GroundTruth gt = trace_ground_truth(asset_, s.origin, s.dir, 0.0f, s.length,
                                                              SampleSlot{params.seed, params.step, i});
                    nb_segment_points(asset_.encoding, s.origin, s.dir, 0.0f, s.length, queries[n].points[0],
                                      queries[n].points[1], queries[n].points[2]);
                    meta[n] = {neural::make_targets(gt.hit, gt.depth, gt.normal, gt.albedo, gt.visibility), gt.hit, s.cut, s.leaf};
                    n++;
                }
                if (n == 0) break;
                neural::forward_tile(weights_, std::span<const neural::SegmentQuery>(queries.data(), n), tile);
                for (uint32_t j = 0; j < n; ++j) {
                    const neural::Outputs y = tile.output(j);
                    if (!std::isfinite(y[0] + y[1] + y[2] + y[3] + y[4] + y[5] + y[6] + y[7])) {
                        ts.non_finite = true; // reported as a skipped step; never fed to the loss
                        continue;             // (its dL/dy stays 0; the step is skipped anyway)
                    }
                    neural::Outputs dl_dy{};
                    std::array<float, NB_MLP_OUTPUTS> slot{};
                    const float total = neural::composite_loss(y, meta[j].target, loss_cfg_, &dl_dy, &slot);
                    tile.set_dl_dy(j, dl_dy);
                    // Unweighted terms for the log; normal and albedo as means over their 3 channels.
                    ts.terms.visibility += slot[NB_OUT_VISIBILITY] / loss_cfg_.w_visibility;
                    ts.terms.depth += slot[NB_OUT_DEPTH] / loss_cfg_.w_depth;
                    ts.terms.normal += (slot[NB_OUT_NORMAL] + slot[NB_OUT_NORMAL + 1] + slot[NB_OUT_NORMAL + 2]) /
                                       (3.0f * loss_cfg_.w_normal);
                    ts.terms.albedo += (slot[NB_OUT_ALBEDO] + slot[NB_OUT_ALBEDO + 1] + slot[NB_OUT_ALBEDO + 2]) /
                                       (3.0f * loss_cfg_.w_albedo);
                    ts.terms.total += total;
                    ts.samples++;
                    if (meta[j].hit) ts.hits++;
                    if (meta[j].cut == 0) {
                        ts.leaf_loss[size_t(meta[j].leaf)] += total;
                        ts.leaf_samples[size_t(meta[j].leaf)]++;
                    }
                }
                neural::backward_tile(weights_, tile, ts.grads.mlp.data(), sink);
            }
        };
        run_on_threads(n_threads, work);

        // Reduce.
        StepStats st;
        st.leaves.assign(leaves, LeafStepStats{});
        bool non_finite = false;
        LossTerms sum;
        std::fill(mlp_grad_.begin(), mlp_grad_.end(), 0.0f);
        std::fill(grid_grad_.begin(), grid_grad_.end(), 0.0f);
        for (unsigned t = 0; t < n_threads; ++t) {
            const ThreadState& ts = per_thread_[t];
            st.samples += ts.samples;
            st.hits += ts.hits;
            st.draws += ts.draws;
            non_finite = non_finite || ts.non_finite;
            sum.visibility += ts.terms.visibility;
            sum.depth += ts.terms.depth;
            sum.normal += ts.terms.normal;
            sum.albedo += ts.terms.albedo;
            sum.total += ts.terms.total;
            for (size_t i = 0; i < leaves; ++i) {
                st.leaves[i].loss_sum += ts.leaf_loss[i];
                st.leaves[i].samples += ts.leaf_samples[i];
                st.leaves[i].draws += ts.leaf_draws[i];
            }
            for (size_t i = 0; i < mlp_grad_.size(); ++i) mlp_grad_[i] += ts.grads.mlp[i];
            if (!dense_grid_)
                for (const neural::GridGrad<float>& g : ts.grid_sparse) grid_grad_[g.index] += g.grad;
        }
        if (dense_grid_) {
            // Dense grid gradients: reduced in slices on all threads (thread order per value, as serial).
            auto reduce = [&](unsigned s) {
                const size_t n = grid_grad_.size(), b = n * s / n_threads, e = n * (s + 1) / n_threads;
                for (unsigned t = 0; t < n_threads; ++t) {
                    const float* src = per_thread_[t].grid_grad.data();
                    for (size_t i = b; i < e; ++i) grid_grad_[i] += src[i];
                }
            };
            run_on_threads(n_threads, reduce);
        }
        if (st.samples == 0) {
            st.skipped = true;
            st.skip_reason = "no training ray met a leaf of the cut";
            return st;
        }
        const double inv = 1.0 / double(st.samples);
        const double inv_hits = st.hits ? 1.0 / double(st.hits) : 0.0;
        st.loss.visibility = sum.visibility * inv;
        st.loss.depth = sum.depth * inv_hits;
        st.loss.normal = sum.normal * inv_hits;
        st.loss.albedo = sum.albedo * inv_hits;
        st.loss.total = sum.total * inv;

        // Guard: never let a non-finite value reach the optimiser (then the weights).
        if (non_finite || !std::isfinite(st.loss.total)) {
            st.skipped = true;
            st.skip_reason = non_finite ? "non-finite network output" : "non-finite loss";
            return st;
        }
        const float scale = float(inv); // mean over the batch
        for (float& g : mlp_grad_) g *= scale;
        for (float& g : grid_grad_) g *= scale;
        if (!all_finite(mlp_grad_.data(), mlp_grad_.size()) || !all_finite(grid_grad_.data(), grid_grad_.size())) {
            st.skipped = true;
            st.skip_reason = "non-finite gradient";
            return st;
        }
        adam_.step(weights_, mlp_grad_, grid_grad_, threads_);
        return st;
    }

private:
    // Per drawn sample of a tile: what the loss needs after the batched forward.
    struct TileSample {
        neural::Targets target{};
        bool hit = false;
        uint32_t cut = 0;
        int32_t leaf = -1;
    };

    struct ThreadState {
        neural::Gradients grads;                         // .mlp used (dense); .grid unused
        std::vector<float> grid_grad;                    // dense grid gradient (small tables)
        std::vector<neural::GridGrad<float>> grid_sparse; // sparse grid gradient (large tables)
        std::unique_ptr<neural::BatchTile> tile;
        std::vector<double> leaf_loss;
        std::vector<uint32_t> leaf_samples, leaf_draws;
        LossTerms terms;
        uint32_t samples = 0, hits = 0;
        uint64_t draws = 0;
        bool non_finite = false;
        void reset(const neural::NetworkWeights& w, size_t leaves, bool dense) {
            grads.reset();
            if (dense)
                grid_grad.assign(w.grid.size(), 0.0f);
            else
                grid_sparse.clear();
            leaf_loss.assign(leaves, 0.0);
            leaf_samples.assign(leaves, 0u);
            leaf_draws.assign(leaves, 0u);
            terms = LossTerms{};
            samples = hits = 0;
            draws = 0;
            non_finite = false;
        }
    };

    const TrainingAsset& asset_;
    neural::NetworkWeights weights_;
    neural::Adam adam_;
    neural::LossConfig loss_cfg_; // paper weights 2, 2, 1, 1; linearised normals; masking
    unsigned threads_ = 1;
    std::vector<ThreadState> per_thread_;
    std::vector<float> mlp_grad_, grid_grad_;
    static constexpr size_t kDenseGridValues = size_t(1) << 22;
    bool dense_grid_ = true;
};

} // namespace

std::unique_ptr<TrainerBackend> make_cpu_backend(const TrainingAsset& asset, const NeuralConfig& config,
                                                 const neural::AdamConfig& adam, const CpuBackendOptions& options,
                                                 uint64_t seed) {
    return std::make_unique<CpuBackend>(asset, config, adam, options, seed);
}

} // namespace nbvh
