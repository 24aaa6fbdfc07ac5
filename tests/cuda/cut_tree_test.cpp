// The compact cut tree of the CUDA sampler (trainer/cuda/cut_tree.h): host code, so these run without a
// GPU too (built where CUDA is, as part of nbvh_cuda_tests; CI builds them). The GPU sampler over it is checked against the CPU's first_leaf_of_cut in cuda_backend_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <stdexcept>

#include "tests/cuda/cuda_test_support.h"
#include "tests/trainer/trainer_test_scenes.h"
#include "trainer/cuda/cut_tree.h"

namespace nbvh {
namespace {

using cuda::CutNode;
using cuda::kCutLeafTag;
using cuda::kCutNone;

struct BaseArrays {
    std::vector<float> boxes;
    std::vector<uint32_t> children;
};

BaseArrays flatten(const TrainingAsset& a) { // as cuda_backend.cpp flatten_asset
    BaseArrays f;
    for (size_t i = 0; i < a.bvh().nodes.size(); ++i) {
        for (int k = 0; k < 3; ++k) f.boxes.push_back(a.node_boxes[i].lo[k]);
        for (int k = 0; k < 3; ++k) f.boxes.push_back(a.node_boxes[i].hi[k]);
        f.children.push_back(a.bvh().nodes[i].left);
        f.children.push_back(a.bvh().nodes[i].right);
    }
    return f;
}

// Walks the base BVH and the compact tree together: same boxes (as centre and half extent), same children
// order, cut leaves carry their slot and end the walk. Returns the compact nodes reached.
size_t check_isomorphic(const TrainingAsset& a, const TrainingCut& cut, const std::vector<CutNode>& nodes,
                        uint32_t base_root, uint32_t compact_root, std::vector<uint32_t>& leaves_seen) {
    std::vector<std::pair<uint32_t, uint32_t>> stack{{base_root, compact_root}};
    size_t reached = 0;
    while (!stack.empty()) {
        const auto [b, c] = stack.back();
        stack.pop_back();
        EXPECT_LT(c, nodes.size());
        if (c >= nodes.size()) return reached;
        reached++;
        const CutNode& n = nodes[c];
        for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(n.centre[k], 0.5f * (a.node_boxes[b].lo[k] + a.node_boxes[b].hi[k]));
            EXPECT_EQ(n.half[k], 0.5f * (a.node_boxes[b].hi[k] - a.node_boxes[b].lo[k]));
        }
        const int32_t slot = cut.leaf_of_base_node[b];
        if (slot >= 0) {
            EXPECT_EQ(n.right, kCutLeafTag);
            EXPECT_EQ(n.left, uint32_t(slot));
            leaves_seen.push_back(uint32_t(slot));
            continue;
        }
        const BvhNode& bn = a.bvh().nodes[b];
        EXPECT_EQ(n.left == kCutNone, bn.left == BVH_INVALID);
        EXPECT_EQ(n.right == kCutNone, bn.right == BVH_INVALID);
        if (bn.left != BVH_INVALID && n.left != kCutNone) {
            EXPECT_EQ(n.left, c + 1) << "depth-first: the left child follows its parent";
            stack.push_back({bn.left, n.left});
        }
        if (bn.right != BVH_INVALID && n.right != kCutNone) stack.push_back({bn.right, n.right});
    }
    return reached;
}

TEST(CutTree, MirrorsTheBaseBvhDownToTheCut) {
    const Scene scene = test::scene_of(test::height_field(24, 0.3f, 1.0f, glm::vec3(0.0f)));
    const TrainingAsset asset = make_training_asset(scene, 0);
    const BaseArrays f = flatten(asset);
    for (uint32_t depth : {0u, 1u, 3u, 6u, 40u}) {
        const TrainingCut cut = test::cut_at_depth(asset, depth);
        std::vector<CutNode> nodes;
        std::vector<uint32_t> roots;
        const std::vector<uint32_t> parts{0u};
        cuda::append_cut_tree(f.boxes, f.children, cut.leaf_of_base_node, parts, nodes, roots);
        ASSERT_EQ(roots.size(), 1u);
        EXPECT_EQ(roots[0], 0u);
        std::vector<uint32_t> seen;
        EXPECT_EQ(check_isomorphic(asset, cut, nodes, 0, roots[0], seen), nodes.size()) << "depth " << depth;
        // Every cut leaf once; a cut of n leaves has 2n - 1 nodes above and at it (binary base BVH).
        std::sort(seen.begin(), seen.end());
        ASSERT_EQ(seen.size(), cut.size());
        for (size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], i);
        EXPECT_EQ(nodes.size(), 2 * cut.size() - 1) << "depth " << depth;
        if (depth == 40u) {
            EXPECT_EQ(nodes.size(), asset.bvh().nodes.size()); // the cut is the base leaves
        }
    }
}

TEST(CutTree, SeveralCutsAndPartsAppendWithTheirOwnRoots) {
    const Scene scene = test::scene_of(test::height_field(16, 0.2f, 1.0f, glm::vec3(0.0f)));
    const TrainingAsset asset = make_training_asset(scene, 0);
    const BaseArrays f = flatten(asset);
    const Bvh& bvh = asset.bvh();
    // Two "parts" (the root's two subtrees) and two cuts (LoDs), as cuda_core.cu set_cuts appends them.
    const std::vector<uint32_t> parts{bvh.nodes[0].left, bvh.nodes[0].right};
    const TrainingCut fine = test::cut_at_depth(asset, 5), coarse = test::cut_at_depth(asset, 2);
    std::vector<CutNode> nodes;
    std::vector<uint32_t> roots;
    cuda::append_cut_tree(f.boxes, f.children, fine.leaf_of_base_node, parts, nodes, roots);
    const size_t fine_nodes = nodes.size();
    cuda::append_cut_tree(f.boxes, f.children, coarse.leaf_of_base_node, parts, nodes, roots);
    ASSERT_EQ(roots.size(), 4u); // [cut * parts + part]
    EXPECT_EQ(roots[0], 0u);
    EXPECT_EQ(roots[2], fine_nodes);
    std::vector<uint32_t> seen_fine, seen_coarse;
    for (int p = 0; p < 2; ++p) {
        check_isomorphic(asset, fine, nodes, parts[p], roots[p], seen_fine);
        check_isomorphic(asset, coarse, nodes, parts[p], roots[2 + p], seen_coarse);
    }
    EXPECT_EQ(seen_fine.size(), fine.size());
    EXPECT_EQ(seen_coarse.size(), coarse.size());
}

TEST(CutTree, OneChildNodesAndBaseLeavesBelowNoCutLeaf) {
    // Base: 0 -> (1, none); 1 -> (2, 3); 2 and 3 are base leaves; the cut holds only node 2, so node 3 is
    // a base leaf below no cut leaf (the sampler's walk skips it: no children, no slot).
    std::vector<float> boxes;
    for (int i = 0; i < 4; ++i)
        for (float v : {float(-i), 0.0f, 0.0f, float(i) + 1.0f, 1.0f, 1.0f}) boxes.push_back(v);
    const std::vector<uint32_t> children{1, kCutNone, 2, 3, kCutNone, kCutNone, kCutNone, kCutNone};
    const std::vector<int32_t> leaf_of{-1, -1, 0, -1};
    std::vector<CutNode> nodes;
    std::vector<uint32_t> roots;
    cuda::append_cut_tree(boxes, children, leaf_of, {0}, nodes, roots);
    ASSERT_EQ(nodes.size(), 4u);
    EXPECT_EQ(roots, (std::vector<uint32_t>{0u}));
    EXPECT_EQ(nodes[0].left, 1u);
    EXPECT_EQ(nodes[0].right, kCutNone);
    EXPECT_EQ(nodes[1].left, 2u);
    EXPECT_EQ(nodes[1].right, 3u);
    EXPECT_EQ(nodes[2].left, 0u); // slot 0
    EXPECT_EQ(nodes[2].right, kCutLeafTag);
    EXPECT_EQ(nodes[3].left, kCutNone);
    EXPECT_EQ(nodes[3].right, kCutNone);
    for (uint32_t i = 0; i < 4; ++i) {
        EXPECT_EQ(nodes[i].centre[0], 0.5f); // box [-i, i + 1]
        EXPECT_EQ(nodes[i].half[0], float(i) + 0.5f);
    }
}

TEST(CutTree, BoxesNoRayCrossesAreLeftOutWithTheirSubtrees) {
    // The CPU's clip rejects an empty or non-finite box whatever the ray, so its subtree is never walked:
    // the tree leaves it out (the GPU's branch-free clip_regular needs every kept box regular).
    // Base: 0 -> (1, 2); 1 (NaN bound) -> (3, none); 2 (empty) and 3 are leaves, 3 in the cut.
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::vector<float> boxes{-1, -1, -1, 1, 1, 1, -1, nan, -1, 1, 1, 1, 1, 0, 0, -1, 1, 1, 0, 0, 0, 1, 1, 1};
    const std::vector<uint32_t> children{1, 2, 3, kCutNone, kCutNone, kCutNone, kCutNone, kCutNone};
    const std::vector<int32_t> leaf_of{-1, -1, -1, 0};
    std::vector<CutNode> nodes;
    std::vector<uint32_t> roots;
    cuda::append_cut_tree(boxes, children, leaf_of, {0}, nodes, roots);
    ASSERT_EQ(nodes.size(), 1u);
    EXPECT_EQ(roots, (std::vector<uint32_t>{0u}));
    EXPECT_EQ(nodes[0].left, kCutNone);
    EXPECT_EQ(nodes[0].right, kCutNone);
    // A root no ray crosses: the part has no root (the sampler finds no leaf there).
    nodes.clear();
    roots.clear();
    cuda::append_cut_tree(boxes, children, leaf_of, {2, 0}, nodes, roots);
    EXPECT_EQ(roots, (std::vector<uint32_t>{kCutNone, 0u}));
    // A finite box beyond 1e37 (the loader stops at 1e9): refused, not clipped with overflowing bounds.
    boxes[3] = 3e37f;
    nodes.clear();
    roots.clear();
    EXPECT_THROW(cuda::append_cut_tree(boxes, children, leaf_of, {0}, nodes, roots), std::invalid_argument);
    // The left child dropped, the right one kept: it is linked from the parent's right field.
    const std::vector<float> two{-1, -1, -1, 1, 1, 1, -1, nan, -1, 1, 1, 1, 0, 0, 0, 1, 1, 1};
    nodes.clear();
    roots.clear();
    cuda::append_cut_tree(two, {1, 2, kCutNone, kCutNone, kCutNone, kCutNone}, {-1, -1, 0}, {0}, nodes,
                          roots);
    ASSERT_EQ(nodes.size(), 2u);
    EXPECT_EQ(nodes[0].left, kCutNone);
    EXPECT_EQ(nodes[0].right, 1u);
    EXPECT_EQ(nodes[1].right, kCutLeafTag);
    const float c[3] = {0.0f, 0.0f, 0.0f}, h[3] = {1.0f, 0.0f, 1e30f};
    EXPECT_EQ(cuda::classify_cut_box(c, h), cuda::CutBox::regular);
}

TEST(CutTree, RejectsInconsistentInput) {
    std::vector<CutNode> nodes;
    std::vector<uint32_t> roots;
    const std::vector<float> boxes(6 * 3, 0.0f);
    const std::vector<int32_t> no_cut(3, -1);
    // Sizes that do not match, a root or child outside the BVH, a cycle: errors, never a hang.
    EXPECT_THROW(cuda::append_cut_tree(boxes, {1, 2}, no_cut, {0}, nodes, roots), std::invalid_argument);
    EXPECT_THROW(cuda::append_cut_tree(boxes, {1, 2, kCutNone, kCutNone, kCutNone, kCutNone}, no_cut, {3}, nodes, roots),
                 std::invalid_argument);
    EXPECT_THROW(cuda::append_cut_tree(boxes, {1, 7, kCutNone, kCutNone, kCutNone, kCutNone}, no_cut, {0}, nodes, roots),
                 std::invalid_argument);
    EXPECT_THROW(cuda::append_cut_tree(boxes, {1, 2, 0, kCutNone, kCutNone, kCutNone}, no_cut, {0}, nodes, roots),
                 std::invalid_argument);
    // An empty base BVH: one empty root per part (the sampler finds no leaf and starves the slot).
    nodes.clear();
    roots.clear();
    cuda::append_cut_tree({}, {}, {}, {0, 0}, nodes, roots);
    EXPECT_TRUE(nodes.empty());
    EXPECT_EQ(roots, (std::vector<uint32_t>{kCutNone, kCutNone}));
}

} // namespace
} // namespace nbvh
