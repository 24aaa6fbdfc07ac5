// Shared by the CUDA trainer tests: the skip without a GPU, a mesh's training asset, a step on one fixed
// cut (and test_cuts.h: a fixed N-BVH cut).
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "tests/trainer/test_cuts.h"
#include "tests/trainer/trainer_test_scenes.h"
#include "trainer/cuda/cuda_backend.h"
#include "trainer/training_asset.h"
#include "trainer/training_rays.h"

#define REQUIRE_GPU()                                                                            \
    do {                                                                                         \
        if (!::nbvh::cuda_backend_available()) GTEST_SKIP() << "no usable CUDA GPU";            \
    } while (0)

namespace nbvh::test {

// A scene with one neural instance of `mesh` (scene_of) and its training asset, which points at the
// scene: built in place, not copied.
struct MeshAsset {
    Scene scene;
    TrainingAsset asset;
    explicit MeshAsset(Mesh mesh) : scene(scene_of(std::move(mesh))), asset(make_training_asset(scene, 0)) {}
    MeshAsset(const MeshAsset&) = delete;
    MeshAsset& operator=(const MeshAsset&) = delete;
};

// Step `step` of `batch` samples on the one cut `cut` (cut version 1).
inline StepParams fixed_cut_step(uint32_t step, uint32_t batch, uint64_t seed, const TrainingCut& cut) {
    StepParams p;
    p.step = step;
    p.batch_size = batch;
    p.seed = seed;
    p.cuts = {&cut};
    p.cut_version = 1;
    return p;
}

} // namespace nbvh::test
