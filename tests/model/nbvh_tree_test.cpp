// Tree-cut invariants on a synthetic base BVH: splitting, the schedule on a real cut, LoD cuts and the
// two-child GPU layout.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "engine/neural/nbvh_tree.h"
#include "tests/model/synthetic_bvh.h"
#include "trainer/split_scheduler.h"

namespace nbvh {
namespace {

// Every structural invariant the renderer and the model file rely on.
void expect_valid(const NbvhTree& t) {
    const auto& n = t.nodes();
    ASSERT_FALSE(n.empty());
    std::vector<int> refs(n.size(), 0);
    for (uint32_t i = 0; i < n.size(); ++i) {
        if (!n[i].has_children()) continue;
        ASSERT_GT(n[i].left, i);
        ASSERT_LT(n[i].left + 1, n.size());
        refs[n[i].left]++;
        refs[n[i].left + 1]++;
        EXPECT_EQ(n[n[i].left].parent, i);
        EXPECT_EQ(n[n[i].left].depth, n[i].depth + 1);
        // Children lie inside the parent (a SAH BVH's parent box is the union of its children).
        for (uint32_t c : {n[i].left, n[i].left + 1}) {
            EXPECT_TRUE(glm::all(glm::greaterThanEqual(n[c].bounds.lo, n[i].bounds.lo)));
            EXPECT_TRUE(glm::all(glm::lessThanEqual(n[c].bounds.hi, n[i].bounds.hi)));
        }
    }
    EXPECT_EQ(refs[0], 0);
    for (uint32_t i = 1; i < n.size(); ++i) EXPECT_EQ(refs[i], 1) << "node " << i;
    EXPECT_EQ(t.leaves().size(), t.leaf_count());
    EXPECT_EQ(t.node_count(), 2 * t.leaf_count() - 1);
}

TEST(NbvhTree, StartsAtTheRoot) {
    const Bvh base = test::make_complete_bvh(4);
    NbvhTree t(base);
    EXPECT_EQ(t.node_count(), 1u);
    EXPECT_EQ(t.leaves(), std::vector<uint32_t>{0});
    EXPECT_EQ(t.node(0).base_node, 0u);
    EXPECT_TRUE(t.can_split(0));
    expect_valid(t);
}

TEST(NbvhTree, SplitAppendsBaseChildren) {
    const Bvh base = test::make_complete_bvh(2);
    NbvhTree t(base);
    auto [l, r] = t.split(0);
    EXPECT_EQ(l, 1u);
    EXPECT_EQ(r, 2u);
    EXPECT_EQ(t.node(1).base_node, base.nodes[0].left);
    EXPECT_EQ(t.node(2).base_node, base.nodes[0].right);
    EXPECT_FALSE(t.can_split(0)); // interior now
    t.split(2);
    EXPECT_EQ(t.leaves(), (std::vector<uint32_t>{1, 3, 4}));
    // Depth 2 reached: base leaves can't split.
    EXPECT_TRUE(t.node(3).final_leaf);
    EXPECT_FALSE(t.can_split(3));
    EXPECT_TRUE(t.can_split(1));
    expect_valid(t);
}

TEST(NbvhTree, SplitManySkipsDuplicatesAndUnsplittable) {
    const Bvh base = test::make_complete_bvh(1);
    NbvhTree t(base);
    const std::vector<uint32_t> want{0, 0, 0};
    EXPECT_EQ(t.split_many(want), 1u);
    const std::vector<uint32_t> again{0, 1, 2, 7}; // 0 interior, 1 and 2 base leaves, 7 out of range
    EXPECT_EQ(t.split_many(again), 0u);
    EXPECT_EQ(t.node_count(), 3u);
}

TEST(NbvhTree, MinDepthCut) {
    const Bvh base = test::make_complete_bvh(5);
    NbvhTree t(base, 1, 3);
    EXPECT_EQ(t.leaf_count(), 8u);
    for (uint32_t leaf : t.leaves()) EXPECT_EQ(t.node(leaf).depth, 3u);
    expect_valid(t);
}

// The schedule on a real cut reproduces the simulated count when the base BVH is deep enough.
TEST(NbvhTree, ChessScheduleOnDeepBaseGives25249Nodes) {
    const Bvh base = test::make_complete_bvh(17);
    NbvhTree t(base);
    SplitScheduler scheduler(SplitSchedule::chess());
    std::mt19937 rng(7);
    for (uint32_t step = 0; step <= 3000; ++step) {
        const uint32_t k = scheduler.splits_at(step);
        if (k == 0) continue;
        // Stand-in for the loss ranking: a random order over the splittable leaves.
        std::vector<uint32_t> leaves = t.leaves();
        std::erase_if(leaves, [&](uint32_t i) { return !t.can_split(i); });
        std::shuffle(leaves.begin(), leaves.end(), rng);
        leaves.resize(std::min<size_t>(leaves.size(), k));
        ASSERT_EQ(t.split_many(leaves), leaves.size());
    }
    EXPECT_EQ(t.node_count(), 25249u);
    t.finish_lods();
    EXPECT_FALSE(t.can_split(t.leaves()[0])); // frozen
    expect_valid(t);
}

TEST(NbvhTree, LevelsOfDetailAreNestedCuts) {
    const Bvh base = test::make_complete_bvh(8);
    NbvhTree t(base, 3);
    std::mt19937 rng(1);
    std::vector<uint32_t> counts;
    for (uint32_t lod_round = 0; lod_round < 3; ++lod_round) {
        for (int s = 0; s < 20; ++s) {
            std::vector<uint32_t> leaves = t.leaves();
            t.split_many(std::vector<uint32_t>{leaves[rng() % leaves.size()]});
        }
        counts.push_back(t.node_count());
        EXPECT_EQ(t.register_lod(), 2 - lod_round); // coarsest first
    }
    EXPECT_TRUE(t.frozen());
    expect_valid(t);
    // LoD 2 = first registered cut (coarsest), LoD 0 = final cut.
    EXPECT_EQ(t.node_count_at(2), counts[0]);
    EXPECT_EQ(t.node_count_at(1), counts[1]);
    EXPECT_EQ(t.node_count_at(0), counts[2]);
    EXPECT_EQ(t.node_count_at(0), t.node_count());
    for (uint32_t lod = 0; lod < 3; ++lod) {
        const std::vector<uint32_t> leaves = t.leaves_at(lod);
        EXPECT_EQ(t.node_count_at(lod), 2 * leaves.size() - 1);
        // Leaves of a cut partition the root: their parents are interior at that LoD.
        for (uint32_t leaf : leaves) {
            EXPECT_TRUE(t.is_leaf_at(leaf, lod));
            if (leaf != 0) {
                EXPECT_FALSE(t.is_leaf_at(t.node(leaf).parent, lod));
            }
            EXPECT_LE(t.node(leaf).lod, lod);
        }
    }
}

TEST(NbvhTree, FinishLodsDuplicatesTheFinalCut) {
    const Bvh base = test::make_complete_bvh(4);
    NbvhTree t(base, 4);
    t.split(0);
    EXPECT_EQ(t.register_lod(), 3u);
    t.split(1);
    t.finish_lods();
    EXPECT_EQ(t.node_count_at(3), 3u);
    for (uint32_t lod = 0; lod < 3; ++lod) EXPECT_EQ(t.node_count_at(lod), 5u);
}

// Walks a GPU layout like the shader would and collects the leaf refs.
std::vector<uint32_t> gpu_leaves(const std::vector<GpuBvhNode>& g) {
    std::vector<uint32_t> out;
    std::vector<uint32_t> stack{0};
    while (!stack.empty()) {
        const GpuBvhNode& n = g.at(stack.back());
        stack.pop_back();
        for (uint32_t ref : {n.left, n.right}) {
            if (ref == NB_CHILD_NONE) continue;
            if (nb_is_leaf(ref)) {
                EXPECT_EQ(nb_leaf_count(ref), 1u);
                out.push_back(nb_leaf_first(ref));
            } else {
                stack.push_back(ref);
            }
        }
    }
    std::sort(out.begin(), out.end());
    return out;
}

TEST(NbvhTree, GpuLayoutPerLod) {
    const Bvh base = test::make_complete_bvh(6);
    NbvhTree t(base, 2);
    for (int i = 0; i < 5; ++i) t.split_many(t.leaves());
    t.register_lod();
    t.split_many(t.leaves());
    t.register_lod();
    for (uint32_t lod = 0; lod < 2; ++lod) {
        const std::vector<GpuBvhNode> g = t.to_gpu_layout(lod);
        std::vector<uint32_t> leaves = t.leaves_at(lod);
        std::sort(leaves.begin(), leaves.end());
        EXPECT_EQ(g.size(), leaves.size() - 1); // one GPU node per interior node
        EXPECT_EQ(gpu_leaves(g), leaves);
        // Child boxes in the GPU node are the N-BVH node boxes.
        const GpuBvhNode& root = g[0];
        EXPECT_EQ(root.lmin, t.node(1).bounds.lo);
        EXPECT_EQ(root.rmax, t.node(2).bounds.hi);
    }
}

TEST(NbvhTree, GpuLayoutOfALeafRoot) {
    const Bvh base = test::make_complete_bvh(3);
    NbvhTree t(base);
    t.finish_lods();
    const std::vector<GpuBvhNode> g = t.to_gpu_layout(0);
    ASSERT_EQ(g.size(), 1u);
    EXPECT_EQ(gpu_leaves(g), std::vector<uint32_t>{0});
    EXPECT_GT(g[0].rmin.x, g[0].rmax.x); // empty right child: no ray enters it
}

TEST(NbvhTree, FromNodesDerivesLinks) {
    const Bvh base = test::make_complete_bvh(5);
    NbvhTree t(base);
    for (int i = 0; i < 3; ++i) t.split_many(t.leaves());
    t.finish_lods();
    std::vector<NbvhNode> stored = t.nodes();
    for (NbvhNode& n : stored) { n.parent = 12345; n.depth = 99; }
    NbvhTree u = NbvhTree::from_nodes(stored, 1);
    expect_valid(u);
    EXPECT_EQ(u.max_depth(), 3u);
    EXPECT_FALSE(u.can_split(u.leaves()[0]));
}

} // namespace
} // namespace nbvh
