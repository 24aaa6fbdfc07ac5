// Shared by the CUDA trainer tests: the skip without a GPU (and test_cuts.h: a fixed N-BVH cut).
#pragma once
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "tests/trainer/test_cuts.h"
#include "trainer/cuda/cuda_backend.h"
#include "trainer/training_asset.h"
#include "trainer/training_rays.h"

#define REQUIRE_GPU()                                                                            \
    do {                                                                                         \
        if (!::nbvh::cuda_backend_available()) GTEST_SKIP() << "no usable CUDA GPU";            \
    } while (0)
