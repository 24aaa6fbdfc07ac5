// Live training from the viewer (app/viewer/live_training.h) without a window: the worker trains a small
// neural sphere on the CPU backend, publishes snapshot models every k steps and the final one, records
// the loss of every step; pause holds it between steps, stop ends it; bad starts are one-line errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "app/viewer/live_training.h"
#include "assets/procedural_mesh.h"
#include "engine/core/error.h"

namespace nbvh::viewer {
namespace {

Scene sphere_scene(bool neural) {
    Scene s;
    Material m;
    m.name = "grey";
    m.base_color = glm::vec4(0.6f, 0.6f, 0.6f, 1.0f);
    s.materials.push_back(m);
    s.meshes.push_back(assets::make_sphere("ball", 1.0f, 24, 12, 0));
    Instance i;
    i.name = "ball_node";
    i.mesh = 0;
    i.neural = neural;
    s.instances.push_back(i);
    return s;
}

TrainSettings tiny(int steps) {
    TrainSettings t;
    t.steps = steps;
    t.nodes = 31;
    t.batch = 256;
    t.hash_log2 = 10;
    t.threads = 1;
    t.snapshot_every = 10;
    t.backend = "cpu";
    return t;
}

template <class F> bool wait_until(F done, double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (!done()) {
        if (std::chrono::steady_clock::now() > end) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return true;
}

TEST(LiveTraining, SnapshotsThenTheFinalModel) {
    const Scene scene = sphere_scene(true);
    LiveTrainer t;
    t.start(scene, "sphere", tiny(40));
    ASSERT_TRUE(wait_until([&] { return !t.active(); }, 120.0));
    const TrainStatus s = t.status();
    EXPECT_EQ(s.state, "done");
    EXPECT_EQ(s.backend, "cpu");
    EXPECT_EQ(s.step, 40u);
    EXPECT_EQ(s.steps, 40u);
    EXPECT_EQ(s.snapshots, 4u); // after steps 10, 20, 30, and the final model
    ASSERT_EQ(s.loss_history.size(), 40u);
    EXPECT_GT(s.nodes, 1u);
    std::shared_ptr<const std::vector<float>> loss;
    const auto model = t.take_model(&loss);
    ASSERT_NE(model, nullptr);
    EXPECT_EQ(t.take_model(), nullptr); // taken once
    EXPECT_EQ(t.latest_model(), model);
    ASSERT_EQ(model->assets.size(), 1u);
    EXPECT_EQ(model->assets[0].name, "ball");
    EXPECT_EQ(model->meta.steps, 40u);
    EXPECT_EQ(model->meta.source, "sphere");
    // The per-node training loss: one value per model node; the leaves of the final cut trained (finite,
    // positive), and they differ (the loss the split heuristic ranks by).
    ASSERT_NE(loss, nullptr);
    ASSERT_EQ(loss->size(), model->nodes.size());
    const NbvhTree tree = model->tree();
    std::vector<float> leaf_loss;
    for (uint32_t n : tree.leaves_at(0)) {
        ASSERT_TRUE(std::isfinite((*loss)[n])) << "leaf " << n;
        EXPECT_GT((*loss)[n], 0.0f);
        leaf_loss.push_back((*loss)[n]);
    }
    ASSERT_GT(leaf_loss.size(), 1u);
    EXPECT_LT(*std::min_element(leaf_loss.begin(), leaf_loss.end()), *std::max_element(leaf_loss.begin(), leaf_loss.end()));
}

TEST(LiveTraining, NodeLossSumsPerBaseNode) {
    NodeLossSums sums;
    sums.add(3, 2.0, 4);
    sums.add(3, 1.0, 2);
    sums.add(1, 0.5, 1);
    NeuralModel m;
    m.nodes.resize(3);
    m.nodes[0].base_node = 3;
    m.nodes[1].base_node = 1;
    m.nodes[2].base_node = 7; // never trained
    const std::vector<float> l = sums.per_node(m);
    ASSERT_EQ(l.size(), 3u);
    EXPECT_FLOAT_EQ(l[0], 0.5f);
    EXPECT_FLOAT_EQ(l[1], 0.5f);
    EXPECT_TRUE(std::isnan(l[2]));
}

TEST(LiveTraining, PauseHoldsAndStopEnds) {
    const Scene scene = sphere_scene(true);
    LiveTrainer t;
    t.start(scene, "sphere", tiny(1000000));
    ASSERT_TRUE(wait_until([&] { return t.status().step >= 2; }, 120.0));
    t.set_paused(true);
    EXPECT_EQ(t.status().state, "paused");
    std::this_thread::sleep_for(std::chrono::milliseconds(200)); // a step in flight finishes
    const uint32_t held = t.status().step;
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_EQ(t.status().step, held);
    EXPECT_TRUE(t.active());
    EXPECT_THROW(t.start(scene, "sphere", tiny(10)), Error); // one run at a time
    t.set_paused(false);
    ASSERT_TRUE(wait_until([&] { return t.status().step > held; }, 60.0));
    t.stop();
    EXPECT_FALSE(t.active());
    EXPECT_EQ(t.status().state, "stopped");
    EXPECT_LT(t.status().step, 1000000u);
}

TEST(LiveTraining, BadStartsAreOneLineErrors) {
    LiveTrainer t;
    try {
        t.start(sphere_scene(false), "sphere", tiny(10));
        FAIL() << "no neural instance accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("no neural instances"), std::string::npos) << e.what();
    }
    TrainSettings bad = tiny(10);
    bad.hash_log2 = 2;
    EXPECT_THROW(t.start(sphere_scene(true), "sphere", bad), Error);
    EXPECT_FALSE(t.active());
    EXPECT_EQ(t.status().state, "");
}

} // namespace
} // namespace nbvh::viewer
