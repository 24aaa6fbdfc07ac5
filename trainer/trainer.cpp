#include "trainer/trainer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "engine/core/error.h"
#include "engine/core/log.h"
#if defined(NBVH_HAVE_CUDA)
#include "trainer/cuda/cuda_backend.h"
#endif

namespace nbvh {

TrainOptions default_train_options(BackendChoice backend) {
    TrainOptions o;
    // Three levels of detail (paper §3.4), so that rays after the first hit use the coarsest cut by
    // default (render --secondary-lod coarsest): 14 % faster hybrid frames on the default scene and the
    // dragon (results/perf/); LoD 0 trains on a third of the samples, and the switch stays within the
    // study's noise floor but on the dragon (+0.001 FLIP, results/study/). The official code trains one.
    o.lods = 3;
    if (backend == BackendChoice::cuda) {
        // Paper §4 / official defaults: 2^18 rays per batch, 10k steps, T = 18, the code-default
        // schedule (interval 50, last split 2000 -> 2,395 nodes).
        o.network.log2_hash_size = 18;
        o.target_nodes = 2395;
        o.steps = 10000;
        o.split_fraction = 0.2f;
        o.batch_size = 1u << 18;
    } else {
        // CPU: ~1k nodes, T = 15, 2^11 rays, 1000 steps: about 2M samples, a few minutes on 2
        // cores (results/cpu_training.md); the bunny reaches ~99 % visibility agreement with it.
        o.network.log2_hash_size = 15;
        o.target_nodes = 1000;
        o.steps = 1000;
        o.split_fraction = 0.6f;
        o.batch_size = 1u << 11;
    }
    return o;
}

void validate(const TrainOptions& o) {
    if (o.steps == 0) throw Error("--steps must be at least 1");
    if (o.batch_size == 0 || o.batch_size > (1u << 24)) throw Error("--batch must be in [1, 2^24]");
    if (o.target_nodes == 0 || o.target_nodes > NBVH_MAX_NODES) throw Error("--nodes must be in [1, 2^27)");
    if (o.lods == 0 || o.lods > NBVH_MAX_LODS) throw Error(strfmt("--lods must be in [1, %u]", NBVH_MAX_LODS));
    if (o.network.log2_hash_size < 4 || o.network.log2_hash_size > NB_GRID_MAX_LOG2_HASH)
        throw Error(strfmt("--hash-log2 must be in [4, %u]", NB_GRID_MAX_LOG2_HASH));
    if (!(o.split_fraction >= 0.0f && o.split_fraction <= 1.0f)) throw Error("split fraction must be in [0, 1]");
    if (!(o.learning_rate > 0.0f) || !std::isfinite(o.learning_rate)) throw Error("learning rate must be > 0");
    if (!(o.final_lr_factor > 0.0f && o.final_lr_factor <= 1.0f)) throw Error("final lr factor must be in (0, 1]");
}

SplitSchedule make_split_schedule(const TrainOptions& o) {
    SplitSchedule s;
    const uint32_t split_steps = std::max<uint32_t>(1, uint32_t(double(o.steps) * o.split_fraction));
    // About 40 split events (the official default has 40 split steps up to 2000, interval 50).
    s.splitting_interval = std::max<uint32_t>(1, split_steps / 40);
    s.last_split_iteration = split_steps;
    s.start_split_num = 1;
    s.split_interval_scaling = 2.0f;
    // Smallest growth factor whose simulated node count reaches the target (the trainer stops
    // splitting at the target, so overshooting only makes the last events smaller).
    s.split_scaling = 8.0f;
    for (float f = 1.1f; f <= 8.0f; f += 0.05f) {
        SplitSchedule t = s;
        t.split_scaling = f;
        if (simulate_split_schedule(t).nodes >= o.target_nodes) {
            s.split_scaling = f;
            break;
        }
    }
    return s;
}

neural::AdamConfig make_adam_config(const TrainOptions& o) {
    neural::AdamConfig a;
    a.learning_rate = o.learning_rate;
    const uint32_t split_end = make_split_schedule(o).last_split_iteration;
    const uint32_t final_steps = o.steps > split_end ? o.steps - split_end : 0u;
    constexpr uint32_t intervals = 5;
    if (final_steps >= intervals) {
        a.decay_start = split_end;
        a.decay_interval = (final_steps + intervals - 1) / intervals;
        a.decay_base = float(std::pow(double(o.final_lr_factor), 1.0 / intervals));
    } else {
        a.decay_start = o.steps + 1; // too short a final stage: constant
    }
    return a;
}

BackendChoice resolve_backend(BackendChoice choice) {
    if (choice != BackendChoice::automatic) return choice;
#if defined(NBVH_HAVE_CUDA)
    if (cuda_backend_available()) return BackendChoice::cuda;
#endif
    return BackendChoice::cpu;
}

void use_cuda_device(const std::string& uuid) {
    if (uuid.empty()) return;
#if defined(NBVH_HAVE_CUDA)
    cuda_use_device_uuid(uuid);
#else
    throw Error("training on GPU " + uuid +
                " needs the CUDA backend, which this build has not (use --backend cpu)");
#endif
}

std::unique_ptr<TrainerBackend> make_backend(BackendChoice choice, const TrainingAsset& asset,
                                             const TrainOptions& options) {
    choice = resolve_backend(choice);
    if (choice == BackendChoice::cuda) {
#if defined(NBVH_HAVE_CUDA)
        if (!cuda_backend_available()) throw Error("--backend cuda: no usable CUDA GPU was found");
        return make_cuda_backend(asset, options.network, make_adam_config(options), options.seed,
                                 options.deterministic);
#else
        throw Error("--backend cuda: this build has no CUDA backend (nvcc was not found at configure time)");
#endif
    }
    CpuBackendOptions cpu;
    cpu.threads = options.threads;
    return make_cpu_backend(asset, options.network, make_adam_config(options), cpu, options.seed);
}

namespace {

// Error statistics of one N-BVH node since its creation (notes §7), over the steps that trained.
struct NodeStats {
    double loss_sum = 0.0;
    uint64_t samples = 0;
    uint64_t draws = 0;  // rays of the current cut whose first leaf this was (before the roulette)
    double rays = 0.0;   // rays drawn for the current cut while the node was a leaf
    // h = q sqrt(p), q = loss/samples, p = draws/rays: ranks like r = 2 log q + log p (paper §3.2).
    // p is the probability that a training ray meets this leaf first. Rejected samples are redrawn, so
    // the rays drawn per step grow as the roulette rejects more (up to 1/0.005 times): draws per step
    // alive (the official p, whose batches have no redraws) would rank a leaf that lived through cheap
    // steps below a newer one of half its probability.
    double heuristic() const {
        if (samples == 0 || rays <= 0.0) return -1.0;
        const double q = loss_sum / double(samples);
        const double p = double(draws) / rays;
        return q * std::sqrt(p);
    }
};

double steady_seconds() {
    using clock = std::chrono::steady_clock;
    return std::chrono::duration<double>(clock::now().time_since_epoch()).count();
}

} // namespace

TrainResult train_asset(const TrainingAsset& asset, const TrainOptions& options, TrainerBackend& backend,
                        const ProgressCallback& progress) {
    validate(options);
    const SplitSchedule schedule = make_split_schedule(options);
    const neural::AdamConfig adam = make_adam_config(options);
    SplitScheduler scheduler(schedule);
    NbvhTree tree(asset.bvh(), options.lods);
    // Several parts (assets): the cut starts at the part roots; the nodes above them only join the parts
    // and are never a leaf, at any LoD.
    for (;;) {
        std::vector<uint32_t> above;
        for (uint32_t n : tree.leaves())
            if (tree.node(n).base_node < asset.above_parts.size() && asset.above_parts[tree.node(n).base_node])
                above.push_back(n);
        if (above.empty() || tree.split_many(above) == 0) break;
    }
    std::vector<NodeStats> stats(tree.node_count());
    const size_t base_nodes = asset.bvh().nodes.size();

    // cuts[0]: the current cut (statistics); then the registered coarser LoDs.
    std::vector<TrainingCut> cuts(1);
    std::vector<uint32_t> cut0_nodes; // N-BVH node of each slot of cuts[0]
    uint64_t cut_version = 0;
    auto rebuild_cuts = [&] {
        cut0_nodes = tree.leaves();
        std::vector<uint32_t> base_ids;
        auto to_base = [&](const std::vector<uint32_t>& nodes) {
            base_ids.clear();
            for (uint32_t n : nodes) base_ids.push_back(tree.node(n).base_node);
        };
        to_base(cut0_nodes);
        cuts.resize(1);
        cuts[0].assign(base_ids, base_nodes);
        // Coarser registered LoDs (their cuts differ from the current one while it still grows).
        for (uint32_t r = 0; r < tree.registered_lods(); ++r) {
            const uint32_t lod = options.lods - 1 - r;
            if (lod == 0) continue; // LoD 0 is the final cut == cuts[0]
            TrainingCut c;
            to_base(tree.leaves_at(lod));
            c.assign(base_ids, base_nodes);
            cuts.push_back(std::move(c));
        }
        cut_version++;
    };
    rebuild_cuts();

    TrainResult result;
    result.backend = backend.name();
    result.log.reserve(options.steps);
    const double t_start = steady_seconds();
    uint64_t trained_samples = 0;
    uint32_t consecutive_skips = 0;
    const uint32_t split_end = schedule.last_split_iteration;
    bool splitting_done = false;

    std::vector<double> heuristics; // of cut0's leaves, this step
    for (uint32_t step = 0; step < options.steps; ++step) {
        // Survival roulette (paper §3.3): keep = max(h / h_max, 0.005). Each leaf's heuristic (two
        // divisions and a square root) is evaluated once per step: host work between the CUDA backend's
        // steps, 25k leaves at paper-size cuts.
        heuristics.resize(cut0_nodes.size());
        double h_max = 0.0;
        for (size_t i = 0; i < cut0_nodes.size(); ++i) {
            heuristics[i] = stats[cut0_nodes[i]].heuristic();
            h_max = std::max(h_max, heuristics[i]);
        }
        for (size_t i = 0; i < cut0_nodes.size(); ++i) {
            const double h = heuristics[i];
            cuts[0].keep_probability[i] =
                (h < 0.0 || h_max <= 0.0) ? 1.0f : float(std::clamp(h / h_max, 0.005, 1.0));
        }
        const float lr = neural::lr_at_step(adam, step); // what the backend's Adam applies

        StepParams params;
        params.step = step;
        params.batch_size = options.batch_size;
        params.learning_rate = lr;
        params.seed = options.seed;
        for (const TrainingCut& c : cuts) params.cuts.push_back(&c);
        params.cut_version = cut_version;

        const double t0 = steady_seconds();
        StepStats st = backend.step(params);
        const double dt = steady_seconds() - t0;

        if (st.skipped) {
            result.skipped_steps++;
            log_warn("step %u skipped: %s", step, st.skip_reason.c_str());
            if (++consecutive_skips >= options.max_consecutive_skips)
                throw Error(strfmt("training diverged: %u consecutive steps had non-finite losses or gradients (%s)",
                                   consecutive_skips, st.skip_reason.c_str()));
        } else {
            consecutive_skips = 0;
            trained_samples += st.samples;
            NBVH_CHECK(st.leaves.size() == cut0_nodes.size());
            // Every draw picks its cut uniformly (paper §3.4), so the current cut got st.draws / cuts
            // of the rays drawn in expectation, misses and rejected samples included.
            const double cut0_rays = double(st.draws) / double(params.cuts.size());
            for (size_t i = 0; i < cut0_nodes.size(); ++i) {
                NodeStats& ns = stats[cut0_nodes[i]];
                ns.loss_sum += st.leaves[i].loss_sum;
                ns.samples += st.leaves[i].samples;
                ns.draws += st.leaves[i].draws;
                ns.rays += cut0_rays;
            }
        }

        // Splits after the optimiser step (split_scheduler.h contract), capped at the target.
        bool changed = false;
        if (!splitting_done && !tree.frozen()) {
            uint32_t k = scheduler.splits_at(step);
            const uint32_t budget = tree.node_count() >= options.target_nodes
                                        ? 0u
                                        : (options.target_nodes - tree.node_count()) / 2u;
            k = std::min(k, budget);
            if (k > 0) {
                std::vector<std::pair<double, uint32_t>> ranked;
                for (uint32_t n : cut0_nodes)
                    if (tree.can_split(n) && stats[n].samples > 0) ranked.push_back({stats[n].heuristic(), n});
                k = std::min<uint32_t>(k, uint32_t(ranked.size()));
                std::partial_sort(ranked.begin(), ranked.begin() + k, ranked.end(), std::greater<>());
                std::vector<uint32_t> chosen;
                for (uint32_t i = 0; i < k; ++i) chosen.push_back(ranked[i].second);
                if (tree.split_many(chosen) > 0) {
                    stats.resize(tree.node_count());
                    changed = true;
                }
            }
            if (budget == 0 || tree.node_count() + 1 >= options.target_nodes) splitting_done = true;
        }
        if (!tree.frozen() && lod_registration_due(schedule, step, tree.registered_lods(), options.lods)) {
            tree.register_lod();
            changed = true;
        }
        if (changed) rebuild_cuts();

        StepLog entry;
        entry.step = step;
        entry.nodes = tree.node_count();
        entry.leaves = tree.leaf_count();
        entry.learning_rate = lr;
        entry.loss = st.loss;
        entry.skipped = st.skipped;
        entry.seconds = dt;
        result.log.push_back(entry);

        if (progress) {
            TrainProgress p;
            p.step = step + 1;
            p.steps = options.steps;
            p.nodes = tree.node_count();
            p.leaves = tree.leaf_count();
            p.loss = st.loss.total;
            const double elapsed = steady_seconds() - t_start;
            p.samples_per_s = elapsed > 0.0 ? double(trained_samples) / elapsed : 0.0;
            p.eta_s = elapsed / double(step + 1) * double(options.steps - step - 1);
            p.final_stage = step >= split_end;
            progress(p);
        }
    }
    tree.finish_lods();
    result.seconds = steady_seconds() - t_start;
    result.samples_per_s = result.seconds > 0.0 ? double(trained_samples) / result.seconds : 0.0;
    backend.read_weights(result.weights);
    result.tree = std::move(tree);
    if (result.skipped_steps > 0)
        log_warn("%u of %u training steps were skipped (non-finite loss or gradient)", result.skipped_steps,
                 options.steps);
    return result;
}

TrainingCut cut_of_tree(const TrainingAsset& asset, const NbvhTree& tree, uint32_t lod) {
    std::vector<uint32_t> base;
    for (uint32_t n : tree.leaves_at(lod)) base.push_back(tree.node(n).base_node);
    TrainingCut c;
    c.assign(base, asset.bvh().nodes.size());
    return c;
}

void write_train_log_csv(const std::vector<StepLog>& log, const std::string& path) {
    FILE* f = std::fopen(path.c_str(), "w");
    if (!f) throw Error(strfmt("cannot write training log '%s'", path.c_str()));
    std::fprintf(f, "step,nodes,leaves,lr,loss,visibility,depth,normal,albedo,skipped,seconds\n");
    for (const StepLog& s : log)
        std::fprintf(f, "%u,%u,%u,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%.4f\n", s.step, s.nodes, s.leaves,
                     double(s.learning_rate), s.loss.total, s.loss.visibility, s.loss.depth, s.loss.normal,
                     s.loss.albedo, s.skipped ? 1 : 0, s.seconds);
    const bool ok = std::fclose(f) == 0;
    if (!ok) throw Error(strfmt("cannot write training log '%s'", path.c_str()));
}

} // namespace nbvh
