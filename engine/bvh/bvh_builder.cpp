// Binned SAH BVH builder (Wald 2007 "On fast construction of SAH-based BVHs"; madmann91/bvh's
// binned builder for the structure). Iterative (explicit work stack), top-down; large subtrees are built
// on several threads (build_parallel), each as the one-thread build builds it, and laid out in its order.
//
// Robustness rules (issue 2 item 4):
//  - primitives with empty or non-finite bounds are skipped;
//  - axes whose centroid extent is zero (or too small to bin) are not binned; when no axis can be
//    binned (all centroids identical) the node is split in the middle of its primitive range;
//  - SAH areas are computed in double; nodes flat on two axes use the half perimeter instead;
//  - depth stays < NB_BVH_MAX_DEPTH: an SAH split whose child could not reach leaf size by halving
//    within the depth budget is replaced by a median split along the widest centroid axis.
#include <algorithm>
#include <array>
#include <cmath>
#include <future>
#include <limits>
#include <memory>
#include <thread>

#include "engine/bvh/aabb_ops.h"
#include "engine/bvh/bvh.h"
#include "engine/core/error.h"

namespace nbvh {
namespace {

constexpr uint32_t MAX_BINS = 256;
constexpr uint32_t DEPTH_LIMIT = NB_BVH_MAX_DEPTH - 1; // deepest allowed node depth (root = 0)
constexpr uint64_t MAX_PRIMS = uint64_t(1) << NB_LEAF_FIRST_BITS;
// Subtrees with fewer primitives are built on the thread that reaches them.
constexpr uint32_t PARALLEL_MIN_PRIMS = 1u << 14;

struct Bin {
    Aabb bounds;
    uint32_t count = 0;
};

struct Split {
    int axis = -1;          // -1: no SAH split found
    uint32_t bin = 0;       // primitives with bin index < bin go left
    double cost = std::numeric_limits<double>::infinity();
};

// Levels of halving needed until `n` primitives fit in leaves of `leaf` primitives.
uint32_t halving_levels(uint32_t n, uint32_t leaf) {
    uint32_t levels = 0;
    while (n > leaf) {
        n = (n + 1) / 2;
        ++levels;
    }
    return levels;
}

class Builder {
public:
    Builder(std::span<const Aabb> bounds, const BvhBuildOptions& o) : bounds_(bounds) {
        max_leaf_ = std::clamp<uint32_t>(o.max_leaf_size, 1u, NB_LEAF_MAX_COUNT);
        bins_ = std::clamp<uint32_t>(o.bin_count, 2u, MAX_BINS);
        traversal_cost_ = std::isfinite(o.traversal_cost) ? std::max(o.traversal_cost, 0.0f) : 1.0f;
    }

    Bvh build(uint32_t threads) {
        Bvh bvh;
        centroids_ = std::make_shared<std::vector<glm::vec3>>(bounds_.size());
        std::vector<glm::vec3>& centroids = *centroids_;
        for (uint32_t i = 0; i < bounds_.size(); ++i) {
            if (!is_valid(bounds_[i])) continue;
            // Centre computed in double so that huge (finite) bounds do not overflow.
            glm::dvec3 c = 0.5 * (glm::dvec3(bounds_[i].lo) + glm::dvec3(bounds_[i].hi));
            centroids[i] = glm::vec3(c);
            bvh.prim_indices.push_back(i);
        }
        if (bvh.prim_indices.empty()) return bvh;
        if (bvh.prim_indices.size() > MAX_PRIMS)
            throw Error("BVH: too many primitives (" + std::to_string(bvh.prim_indices.size()) + ", at most 2^27)");
        idx_ = bvh.prim_indices.data();
        BvhNode root;
        root.first = 0;
        root.count = uint32_t(bvh.prim_indices.size());
        if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
        // Subtrees are handed to other threads down to the level where there are about 2 per thread.
        uint32_t spawn_levels = 0;
        while (threads > 1 && (1u << spawn_levels) < 2 * threads && spawn_levels < 8) ++spawn_levels;
        bvh.nodes = build_parallel(root, spawn_levels);
        return bvh;
    }

  private:
    // The subtree of `root` (first, count and depth set) as the one-thread build lays it out with root at
    // index 0: the root, its two children, the right child's descendants, then the left child's (the
    // work stack pops the right child first). Indices (children, parents) are local to the vector.
    std::vector<BvhNode> build_sequential(const BvhNode& root) {
        std::vector<BvhNode> nodes;
        nodes.reserve(2 * size_t(root.count));
        nodes_ = &nodes;
        nodes.push_back(root);
        std::vector<uint32_t> stack{0};
        while (!stack.empty()) {
            uint32_t ni = stack.back();
            stack.pop_back();
            if (subdivide(ni)) {
                stack.push_back(nodes[ni].left);
                stack.push_back(nodes[ni].right);
            }
        }
        nodes_ = nullptr;
        return nodes;
    }

    // The same layout, with the left child's subtree built on another thread while this one builds the
    // right child's, down `levels` levels. The split of a node depends only on its primitives and their
    // order in idx_, which the children's builds (disjoint ranges) do not touch: the same tree.
    std::vector<BvhNode> build_parallel(const BvhNode& root, uint32_t levels) {
        if (levels == 0 || root.count < PARALLEL_MIN_PRIMS) return build_sequential(root);
        std::vector<BvhNode> one{root};
        nodes_ = &one;
        const bool split = subdivide(0);
        nodes_ = nullptr;
        if (!split) return one;
        const BvhNode node = one[0], left = one[1], right = one[2];
        Builder other(*this); // its own bins; the same bounds, centroids and index array
        std::future<std::vector<BvhNode>> fl = std::async(
            std::launch::async, [&other, &left, levels] { return other.build_parallel(left, levels - 1); });
        std::vector<BvhNode> r = build_parallel(right, levels - 1);
        std::vector<BvhNode> l = fl.get();
        // [node, left, right] + the right subtree's descendants + the left subtree's.
        // Local index k >= 1 of the right subtree goes to r_base + k, of the left one to l_base + k.
        const uint32_t r_base = 2, l_base = uint32_t(r.size()) + 1;
        std::vector<BvhNode> out;
        out.reserve(1 + r.size() + l.size());
        out.push_back(node);
        auto place = [&out](BvhNode n, uint32_t self, uint32_t base) { // local 0 (the subtree root) -> self
            auto map = [&](uint32_t k) { return k == BVH_INVALID ? k : k == 0 ? self : base + k; };
            n.left = map(n.left);
            n.right = map(n.right);
            n.parent = map(n.parent);
            out.push_back(n);
        };
        BvhNode lr = l[0], rr = r[0];
        place(lr, 1, l_base);
        out.back().parent = 0;
        place(rr, 2, r_base);
        out.back().parent = 0;
        for (size_t k = 1; k < r.size(); ++k) place(r[k], 2, r_base);
        for (size_t k = 1; k < l.size(); ++k) place(l[k], 1, l_base);
        return out;
    }

private:
    // Computes the node's bounds; splits it (turning it into an interior node with two new children)
    // or leaves it a leaf. Returns true when it was split.
    bool subdivide(uint32_t ni) {
        BvhNode& node = (*nodes_)[ni];
        const uint32_t first = node.first, count = node.count, depth = node.depth;
        Aabb nb, cb;
        for (uint32_t i = first; i < first + count; ++i) {
            nb.grow(bounds_[idx_[i]]);
            cb.grow((*centroids_)[idx_[i]]);
        }
        node.bounds = nb;
        if (count == 1) return false;

        uint32_t mid = first;
        const Split split = find_sah_split(nb, cb, first, count);
        const double leaf_cost = double(count);
        bool use_sah = split.axis >= 0;
        if (use_sah && count <= max_leaf_ && split.cost >= leaf_cost) return false; // SAH prefers a leaf
        if (!use_sah && count <= max_leaf_) return false;                          // identical centroids, fits
        if (use_sah) {
            mid = partition_by_bin(cb, split, first, count);
            uint32_t nl = mid - first, nr = count - nl;
            // Depth budget: both children must still be able to reach leaf size by halving.
            if (nl == 0 || nr == 0 || depth + 1 + halving_levels(std::max(nl, nr), max_leaf_) > DEPTH_LIMIT)
                use_sah = false;
        }
        if (!use_sah && count <= max_leaf_) return false; // fits in a leaf (also at the depth limit)
        if (!use_sah) mid = median_split(cb, first, count);

        BvhNode left, right;
        left.first = first;
        left.count = mid - first;
        right.first = mid;
        right.count = first + count - mid;
        left.depth = right.depth = depth + 1;
        left.parent = right.parent = ni;
        NBVH_CHECK(left.count > 0 && right.count > 0 && left.depth <= DEPTH_LIMIT);
        const uint32_t li = uint32_t(nodes_->size());
        nodes_->push_back(left);
        nodes_->push_back(right);
        BvhNode& n = (*nodes_)[ni]; // `node` may dangle after push_back
        n.left = li;
        n.right = li + 1;
        n.count = 0;
        n.first = 0;
        return true;
    }

    // Bin index of a centroid along `axis` (same formula for binning and partitioning). `scale` is
    // finite; a product overflowing to +inf is clamped to the last bin.
    uint32_t bin_of(const glm::vec3& c, int axis, float lo, float scale) const {
        float b = (c[axis] - lo) * scale;
        return b >= float(bins_ - 1) ? bins_ - 1 : (b > 0.0f ? uint32_t(b) : 0u);
    }

    // bins / centroid extent along `axis`, or 0 when the axis cannot be binned.
    float bin_scale(const Aabb& cb, int axis) const {
        const float extent = cb.hi[axis] - cb.lo[axis];
        if (!(extent > 0.0f)) return 0.0f;
        const float scale = float(bins_) / extent;
        return std::isfinite(scale) ? scale : 0.0f;
    }

    Split find_sah_split(const Aabb& nb, const Aabb& cb, uint32_t first, uint32_t count) {
        Split best;
        const bool flat2 = half_area(nb) <= 0.0;
        auto measure = [flat2](const Aabb& b) { return flat2 ? half_perimeter(b) : half_area(b); };
        const double parent = measure(nb);
        if (!(parent > 0.0)) return best; // a point: every centroid is identical anyway
        float scale[3];
        bool any_axis = false;
        for (int axis = 0; axis < 3; ++axis) {
            scale[axis] = bin_scale(cb, axis);
            any_axis |= scale[axis] > 0.0f;
            for (uint32_t b = 0; b < bins_; ++b) bins_of_[axis][b] = Bin{};
        }
        if (!any_axis) return best;
        // One pass over the primitives fills the bins of all three axes.
        for (uint32_t i = first; i < first + count; ++i) {
            const uint32_t p = idx_[i];
            const glm::vec3& c = (*centroids_)[p];
            const Aabb& pb = bounds_[p];
            for (int axis = 0; axis < 3; ++axis) {
                if (scale[axis] == 0.0f) continue;
                Bin& bin = bins_of_[axis][bin_of(c, axis, cb.lo[axis], scale[axis])];
                bin.bounds.grow(pb);
                ++bin.count;
            }
        }
        std::array<double, MAX_BINS> right_measure;
        std::array<uint32_t, MAX_BINS> right_count;
        for (int axis = 0; axis < 3; ++axis) {
            if (scale[axis] == 0.0f) continue;
            const std::array<Bin, MAX_BINS>& bins = bins_of_[axis];
            // Sweep from the right, then from the left evaluating "split before bin b".
            Aabb acc;
            uint32_t n = 0;
            for (uint32_t b = bins_ - 1; b > 0; --b) {
                acc.grow(bins[b].bounds);
                n += bins[b].count;
                right_measure[b] = measure(acc);
                right_count[b] = n;
            }
            acc = Aabb{};
            n = 0;
            for (uint32_t b = 1; b < bins_; ++b) {
                acc.grow(bins[b - 1].bounds);
                n += bins[b - 1].count;
                if (n == 0 || right_count[b] == 0) continue;
                double cost = traversal_cost_ + (measure(acc) * n + right_measure[b] * right_count[b]) / parent;
                if (cost < best.cost) best = Split{axis, b, cost};
            }
        }
        return best;
    }

    uint32_t partition_by_bin(const Aabb& cb, const Split& s, uint32_t first, uint32_t count) {
        const float scale = bin_scale(cb, s.axis);
        const float lo = cb.lo[s.axis];
        uint32_t* mid = std::partition(idx_ + first, idx_ + first + count, [&](uint32_t p) {
            return bin_of((*centroids_)[p], s.axis, lo, scale) < s.bin;
        });
        return uint32_t(mid - idx_);
    }

    // Object median along the widest centroid axis (index middle when all centroids coincide).
    uint32_t median_split(const Aabb& cb, uint32_t first, uint32_t count) {
        const uint32_t mid = first + count / 2;
        glm::vec3 e = cb.extent();
        int axis = (e.x >= e.y && e.x >= e.z) ? 0 : (e.y >= e.z ? 1 : 2);
        if (e[axis] > 0.0f) {
            std::nth_element(idx_ + first, idx_ + mid, idx_ + first + count, [&](uint32_t a, uint32_t b) {
                return (*centroids_)[a][axis] < (*centroids_)[b][axis];
            });
        }
        return mid;
    }

    std::span<const Aabb> bounds_;
    std::shared_ptr<std::vector<glm::vec3>> centroids_; // shared, read-only, by the builders of one build
    std::array<std::array<Bin, MAX_BINS>, 3> bins_of_;
    uint32_t* idx_ = nullptr;
    std::vector<BvhNode>* nodes_ = nullptr;
    uint32_t max_leaf_ = 4, bins_ = 16;
    float traversal_cost_ = 1.0f;
};

} // namespace

Bvh build_bvh(std::span<const Aabb> prim_bounds, const BvhBuildOptions& options) {
    Bvh bvh = Builder(prim_bounds, options).build(options.threads);
    if (options.min_node_extent > 0.0f) pad_node_bounds(bvh, options.min_node_extent);
    return bvh;
}

} // namespace nbvh
