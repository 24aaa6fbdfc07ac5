// A small model of the Stanford bunny trained with the CPU trainer (300 steps, ~200 nodes, 2 LoDs,
// hash 2^14: ~10 s on 2 cores), shared by the neural end-to-end tests (hybrid_render_test,
// secondary_rays_test). Trained once per test executable; needs ../shared (callers check
// NBVH_REQUIRE_SHARED() first).
#pragma once
#include "engine/neural/model_file.h"
#include "engine/scene/scene.h"
#include "trainer/evaluation.h"
#include "trainer/training_asset.h"

namespace nbvh::test {

struct TrainedBunny {
    Scene scene;         // stanford_bunny.glb, every instance neural
    TrainingAsset asset; // object-space triangles + BVH of the trained mesh (points into `scene`)
    NeuralModel model;
    EvalStats check;     // the trainer's accuracy check (CPU reference, 2000 fresh rays, LoD 0 cut)
};

const TrainedBunny& trained_bunny();

} // namespace nbvh::test
