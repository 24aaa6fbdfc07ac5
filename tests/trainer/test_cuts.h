// A fixed N-BVH cut for trainer tests (CPU and CUDA): every base-BVH node at `depth`, or a leaf above it.
#pragma once
#include <cstdint>
#include <vector>

#include "trainer/training_asset.h"
#include "trainer/training_rays.h"

namespace nbvh::test {

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
