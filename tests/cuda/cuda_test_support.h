// Shared by the CUDA trainer tests: the skip without a GPU and a fixed N-BVH cut of a training asset.
#pragma once
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "trainer/cuda/cuda_backend.h"
#include "trainer/training_asset.h"
#include "trainer/training_rays.h"

#define REQUIRE_GPU()                                                                            \
    do {                                                                                         \
        if (!::nbvh::cuda_backend_available()) GTEST_SKIP() << "no usable CUDA GPU";            \
    } while (0)

namespace nbvh::test {

// A cut of the base BVH: every node at `depth` (or a leaf above it).
inline TrainingCut cut_at_depth(const TrainingAsset& a, uint32_t depth) {
    std::vector<uint32_t> leaves;
    std::vector<uint32_t> stack{0};
    while (!stack.empty()) {
        const uint32_t n = stack.back();
        stack.pop_back();
        const BvhNode& node = a.bvh().nodes[n];
        if (node.is_leaf() || node.depth >= depth) {
            leaves.push_back(n);
            continue;
        }
        stack.push_back(node.left);
        stack.push_back(node.right);
    }
    TrainingCut c;
    c.assign(leaves, a.bvh().nodes.size());
    return c;
}

} // namespace nbvh::test
