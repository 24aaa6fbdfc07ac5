// Training acceptance on a real asset (the Stanford Bunny from ../shared/scenes, 69k triangles) with
// a tiny CPU configuration (about 2 minutes on 2 cores): every loss term decreases, and the trained
// network, queried through each fresh ray's first leaf of the final cut with the CPU reference,
// agrees with the triangle ground truth on visibility for >= 95 % of the rays; its depth error
// (|t_pred - t_gt| / segment length, on rays both call a hit) stays below the bound stated below.
#include <gtest/gtest.h>

#include "engine/core/log.h"
#include "engine/scene/gltf_loader.h"
#include "tests/support/test_support.h"
#include "trainer/evaluation.h"
#include "trainer/trainer.h"

using namespace nbvh;

namespace {

// Mean of each term over steps [begin, end).
LossTerms mean_loss(const std::vector<StepLog>& log, size_t begin, size_t end) {
    LossTerms m;
    for (size_t i = begin; i < end; ++i) {
        m.visibility += log[i].loss.visibility;
        m.depth += log[i].loss.depth;
        m.normal += log[i].loss.normal;
        m.albedo += log[i].loss.albedo;
        m.total += log[i].loss.total;
    }
    const double n = double(end - begin);
    m.visibility /= n;
    m.depth /= n;
    m.normal /= n;
    m.albedo /= n;
    m.total /= n;
    return m;
}

} // namespace

TEST(TrainBunny, LossesDecreaseAndVisibilityAgrees) {
    NBVH_REQUIRE_SHARED();
    SceneLoadOptions lo;
    lo.neural_glob = "*";
    const Scene scene = load_gltf(test::scenes_dir() / "stanford_bunny" / "stanford_bunny.glb", lo);
    const TrainingAsset asset = make_training_asset(scene, pick_neural_mesh(scene));

    TrainOptions o = default_train_options(BackendChoice::cpu);
    o.steps = 600;
    o.batch_size = 2048;
    o.target_nodes = 255;
    o.network.log2_hash_size = 14;
    o.seed = 2024;
    auto backend = make_backend(BackendChoice::cpu, asset, o);
    const TrainResult r = train_asset(asset, o, *backend);
    ASSERT_EQ(r.log.size(), o.steps);
    EXPECT_EQ(r.skipped_steps, 0u);

    const LossTerms first = mean_loss(r.log, 0, 10);
    const LossTerms last = mean_loss(r.log, r.log.size() - 50, r.log.size());
    std::printf("loss first 10 steps: total %.4f vis %.4f depth %.4f normal %.4f albedo %.4f\n", first.total,
                first.visibility, first.depth, first.normal, first.albedo);
    std::printf("loss last 50 steps:  total %.4f vis %.4f depth %.4f normal %.4f albedo %.4f\n", last.total,
                last.visibility, last.depth, last.normal, last.albedo);
    EXPECT_LT(last.total, first.total);
    EXPECT_LT(last.visibility, first.visibility);
    EXPECT_LT(last.depth, first.depth);
    EXPECT_LT(last.normal, first.normal);
    EXPECT_LT(last.albedo, first.albedo);

    const EvalStats e = evaluate_network(asset, cut_of_tree(asset, r.tree, 0), r.weights, 20000, 7);
    std::printf("eval: %u rays, visibility agreement %.2f %%, depth MAE %.4f (p90 %.4f) of the segment, "
                "%.5f of the diagonal, normal %.1f deg, %u nodes\n",
                e.rays, 100.0 * e.visibility_agreement, e.depth_mae, e.depth_p90, e.depth_mae_rel_asset,
                e.normal_mean_deg, r.tree.node_count());
    ASSERT_GE(e.rays, 19000u);
    EXPECT_GE(e.visibility_agreement, 0.95);
    // Stated bound: mean depth error below 5 % of the leaf segment length.
    EXPECT_LT(e.depth_mae, 0.05);
}
