// Training from the viewer (issue 13 "Training live"): the neural assets of the scene shown are trained
// on a worker thread (trainer/trainer.h train_asset, CUDA when present else CPU, as `nbvh train`), and
// every `snapshot_every` steps the current cut and weights become a model that the viewer swaps into
// the hybrid view, so the image, the node count and the loss change as the cut grows. Pause blocks
// the worker between steps; stop ends it after the current step (the last snapshot stays).
//
// Snapshots come from a backend wrapper (SnapshotBackend in the .cpp) that sees each step's cut and
// reads the backend's weights, so trainer/ needs no hook: the snapshot's N-BVH is rebuilt from the cut's
// base-BVH leaves (one LoD), the weights are the backend's fp32 masters converted to fp16 as the model
// file stores them. The wrapper also sums each cut leaf's training loss from the step statistics, as
// the trainer does for its split heuristic (trainer.cpp NodeStats: q = loss_sum / samples over the
// steps that trained, from the node's creation), so every published model comes with the mean loss of
// each of its N-BVH nodes (the loss view, loss_view.h; paper Fig. 4).
#pragma once
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "app/viewer/ui_panel.h"
#include "engine/neural/model_file.h"
#include "engine/scene/scene.h"

namespace nbvh::viewer {

// Mean training loss per sample of every node of `model` (index = model node), from sums per base-BVH
// node (NbvhNode::base_node); NaN for nodes that never trained a sample (or have no base node).
struct NodeLossSums {
    std::vector<double> loss_sum;   // per base-BVH node
    std::vector<uint64_t> samples;
    void add(uint32_t base_node, double loss, uint64_t n);
    std::vector<float> per_node(const NeuralModel& model) const;
};

struct TrainStatus {
    std::string state;                // "" (never started), running, paused, done, stopped, failed: MSG
    uint32_t step = 0, steps = 0, nodes = 0;
    double loss = 0.0, eta_s = 0.0;
    uint32_t snapshots = 0;           // models published
    std::vector<float> loss_history;  // the loss of every step (of every 2^k-th once 4096 are kept)
    std::string backend;
};

class LiveTrainer {
public:
    LiveTrainer() = default;
    ~LiveTrainer(); // stops and joins the worker
    LiveTrainer(const LiveTrainer&) = delete;
    LiveTrainer& operator=(const LiveTrainer&) = delete;

    // Trains the neural assets of a copy of `scene` (`source` names it in the model). Throws nbvh::Error
    // for bad options, a scene without neural instances, or while a run is active.
    void start(const Scene& scene, const std::string& source, const TrainSettings& settings);
    // The CUDA device of later runs (trainer.h use_cuda_device: the viewer's GPU of --device gpu:N);
    // empty: CUDA's first.
    void set_cuda_device(std::string uuid) { cuda_uuid_ = std::move(uuid); }
    void set_paused(bool paused);
    void stop();          // asks the worker to stop after its current step and waits for it
    bool active() const;  // the worker runs (training or paused)
    TrainStatus status() const;
    // The newest model not taken yet (a snapshot, or the final model), else null; with `node_loss`, that
    // model's per-node training loss (NodeLoss).
    std::shared_ptr<const NeuralModel> take_model(std::shared_ptr<const std::vector<float>>* node_loss = nullptr);
    // The newest model (for saving), else null.
    std::shared_ptr<const NeuralModel> latest_model() const;

    // Called by the worker (SnapshotBackend): blocks while paused, throws when stopped.
    void checkpoint();
    void publish(std::shared_ptr<const NeuralModel> model, std::shared_ptr<const std::vector<float>> node_loss);
    void record(uint32_t step, uint32_t steps, uint32_t nodes, double loss, double eta_s);

private:
    void join();

    mutable std::mutex mutex_;
    std::condition_variable resume_;
    std::thread worker_;
    std::atomic<bool> active_{false};
    bool paused_ = false, stop_ = false;
    TrainStatus status_;
    std::shared_ptr<const NeuralModel> latest_;
    std::shared_ptr<const std::vector<float>> latest_loss_;
    bool taken_ = true;
    uint32_t history_stride_ = 1;
    std::string cuda_uuid_;
};

} // namespace nbvh::viewer
