#include "app/viewer/live_training.h"

#include <algorithm>
#include <limits>

#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/neural/asset_table.h"
#include "trainer/model_export.h"
#include "trainer/trainer.h"
#include "trainer/training_asset.h"

namespace nbvh::viewer {

namespace {

struct TrainingStopped {}; // thrown through train_asset by checkpoint() (everything there is RAII)

constexpr size_t MAX_HISTORY = 4096;

// Wraps the real backend: waits while paused, and every `every` steps turns the cut of the step
// (params.cuts[0], base-BVH leaves) and the current weights into a model.
class SnapshotBackend final : public TrainerBackend {
public:
    SnapshotBackend(TrainerBackend& inner, LiveTrainer& owner, const TrainingAsset& asset, const TrainOptions& options,
                    const std::string& source, uint32_t every)
        : inner_(inner), owner_(owner), asset_(asset), options_(options), source_(source), every_(every) {}

    const char* name() const override { return inner_.name(); }
    void read_weights(neural::NetworkWeights& out) const override { inner_.read_weights(out); }
    StepStats step(const StepParams& params) override {
        owner_.checkpoint();
        StepStats st = inner_.step(params);
        // The trainer's per-node sums (statistics of the leaves of cuts[0], steps that trained only).
        if (!st.skipped && !params.cuts.empty() && st.leaves.size() == params.cuts[0]->leaves.size())
            for (size_t i = 0; i < st.leaves.size(); ++i)
                sums_.add(params.cuts[0]->leaves[i], st.leaves[i].loss_sum, st.leaves[i].samples);
        if (!st.skipped && (params.step + 1) % every_ == 0 && params.step + 1 < options_.steps && !params.cuts.empty()) {
            auto model = snapshot(*params.cuts[0], params.step + 1);
            owner_.publish(model, node_loss(*model));
        }
        return st;
    }
    std::shared_ptr<const std::vector<float>> node_loss(const NeuralModel& model) const {
        return std::make_shared<const std::vector<float>>(sums_.per_node(model));
    }

private:
    std::shared_ptr<const NeuralModel> snapshot(const TrainingCut& cut, uint32_t steps_done) const {
        // The N-BVH whose leaves are the cut: split from the root until every leaf is a cut node.
        std::vector<uint8_t> in_cut(asset_.bvh().nodes.size(), 0);
        for (uint32_t b : cut.leaves) in_cut[b] = 1;
        NbvhTree tree(asset_.bvh(), 1);
        for (;;) {
            std::vector<uint32_t> split;
            for (uint32_t n : tree.leaves())
                if (!in_cut[tree.node(n).base_node]) split.push_back(n);
            if (split.empty() || tree.split_many(split) == 0) break;
        }
        tree.finish_lods();
        TrainResult r;
        r.tree = std::move(tree);
        inner_.read_weights(r.weights);
        r.backend = inner_.name();
        TrainOptions one_lod = options_;
        one_lod.lods = 1;
        auto m = std::make_shared<NeuralModel>(make_neural_model(asset_, r, one_lod, source_, 0, false));
        m->meta.steps = steps_done;
        return m;
    }

    TrainerBackend& inner_;
    LiveTrainer& owner_;
    const TrainingAsset& asset_;
    TrainOptions options_;
    std::string source_;
    uint32_t every_;
    NodeLossSums sums_;
};

BackendChoice parse_backend(const std::string& s) {
    if (s == "cpu") return BackendChoice::cpu;
    if (s == "cuda") return BackendChoice::cuda;
    return BackendChoice::automatic;
}

} // namespace

void NodeLossSums::add(uint32_t base_node, double loss, uint64_t n) {
    if (base_node >= loss_sum.size()) {
        loss_sum.resize(size_t(base_node) + 1, 0.0);
        samples.resize(size_t(base_node) + 1, 0);
    }
    loss_sum[base_node] += loss;
    samples[base_node] += n;
}

std::vector<float> NodeLossSums::per_node(const NeuralModel& model) const {
    std::vector<float> out(model.nodes.size(), std::numeric_limits<float>::quiet_NaN());
    for (size_t n = 0; n < model.nodes.size(); ++n) {
        const uint32_t b = model.nodes[n].base_node;
        if (b < samples.size() && samples[b] > 0) out[n] = float(loss_sum[b] / double(samples[b]));
    }
    return out;
}

LiveTrainer::~LiveTrainer() { stop(); }

void LiveTrainer::start(const Scene& scene, const std::string& source, const TrainSettings& ts) {
    if (active()) throw Error("training is already running (stop it first)");
    join();
    if (std::none_of(scene.instances.begin(), scene.instances.end(), [](const Instance& i) { return i.neural; }))
        throw Error("the scene has no neural instances to train (a '*_neural' scene, --neural GLOB, or a model)");
    const BackendChoice backend = resolve_backend(parse_backend(ts.backend)); // throws when cuda is missing
    TrainOptions opt = default_train_options(backend);
    opt.steps = uint32_t(ts.steps);
    opt.target_nodes = uint32_t(ts.nodes);
    opt.batch_size = uint32_t(ts.batch);
    opt.network.log2_hash_size = uint32_t(ts.hash_log2);
    opt.lods = uint32_t(ts.lods);
    opt.threads = uint32_t(ts.threads);
    validate(opt); // bad options fail here, on the UI thread, as one line
    const uint32_t every = uint32_t(std::max(1, ts.snapshot_every));
    auto copy = std::make_shared<Scene>(scene); // the worker's own: the view may change meanwhile
    {
        std::lock_guard<std::mutex> lock(mutex_);
        status_ = TrainStatus{};
        status_.state = "running";
        status_.steps = opt.steps;
        status_.backend = backend == BackendChoice::cuda ? "cuda" : "cpu";
        paused_ = stop_ = false;
        latest_.reset();
        latest_loss_.reset();
        taken_ = true;
        history_stride_ = 1;
    }
    active_ = true;
    worker_ = std::thread([this, copy, source, opt, backend, every, uuid = cuda_uuid_] {
        std::string end = "done";
        try {
            if (backend == BackendChoice::cuda) use_cuda_device(uuid); // CUDA's device is per thread
            split_neural_meshes(*copy);
            const std::vector<uint32_t> meshes = neural_meshes(*copy);
            const TrainingAsset asset = make_training_asset(*copy, meshes);
            std::unique_ptr<TrainerBackend> inner = make_backend(backend, asset, opt);
            SnapshotBackend be(*inner, *this, asset, opt, source, every);
            log_info("view: training %s (%u triangles, %zu asset(s)) on %s: %u steps x %u rays, target %u nodes",
                     asset.name.c_str(), asset.triangle_count(), asset.parts.size(), inner->name(), opt.steps,
                     opt.batch_size, opt.target_nodes);
            const TrainResult result = train_asset(asset, opt, be, [this](const TrainProgress& p) {
                record(p.step, p.steps, p.nodes, p.loss, p.eta_s);
            });
            auto model = std::make_shared<NeuralModel>(make_neural_model(asset, result, opt, source, 0));
            publish(model, be.node_loss(*model));
            log_info("view: training done: %u nodes, final loss %.4f, %.1f s", result.tree.node_count(),
                     result.log.empty() ? 0.0 : result.log.back().loss.total, result.seconds);
        } catch (const TrainingStopped&) {
            end = "stopped";
        } catch (const Error& e) {
            end = std::string("failed: ") + e.what();
            log_error("view: training failed: %s", e.what());
        }
        std::lock_guard<std::mutex> lock(mutex_);
        status_.state = end;
        active_ = false;
    });
}

void LiveTrainer::set_paused(bool paused) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!active_) return;
    paused_ = paused;
    status_.state = paused ? "paused" : "running";
    resume_.notify_all();
}

void LiveTrainer::stop() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
        resume_.notify_all();
    }
    join();
}

void LiveTrainer::join() {
    if (worker_.joinable()) worker_.join();
}

bool LiveTrainer::active() const { return active_; }

TrainStatus LiveTrainer::status() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return status_;
}

std::shared_ptr<const NeuralModel> LiveTrainer::take_model(std::shared_ptr<const std::vector<float>>* node_loss) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (taken_) return nullptr;
    taken_ = true;
    if (node_loss) *node_loss = latest_loss_;
    return latest_;
}

std::shared_ptr<const NeuralModel> LiveTrainer::latest_model() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return latest_;
}

void LiveTrainer::checkpoint() {
    std::unique_lock<std::mutex> lock(mutex_);
    resume_.wait(lock, [this] { return !paused_ || stop_; });
    if (stop_) throw TrainingStopped{};
}

void LiveTrainer::publish(std::shared_ptr<const NeuralModel> model,
                          std::shared_ptr<const std::vector<float>> node_loss) {
    std::lock_guard<std::mutex> lock(mutex_);
    latest_ = std::move(model);
    latest_loss_ = std::move(node_loss);
    taken_ = false;
    status_.snapshots++;
}

void LiveTrainer::record(uint32_t step, uint32_t steps, uint32_t nodes, double loss, double eta_s) {
    std::lock_guard<std::mutex> lock(mutex_);
    status_.step = step;
    status_.steps = steps;
    status_.nodes = nodes;
    status_.loss = loss;
    status_.eta_s = eta_s;
    // Every history_stride_-th step; when full, every other entry is dropped and the stride doubles, so
    // the plot keeps its shape and memory stays bounded.
    if ((step - 1) % history_stride_ != 0) return;
    auto& h = status_.loss_history;
    h.push_back(float(loss));
    if (h.size() >= MAX_HISTORY) {
        for (size_t i = 0; i < h.size() / 2; ++i) h[i] = h[2 * i];
        h.resize(h.size() / 2);
        history_stride_ *= 2;
    }
}

} // namespace nbvh::viewer
