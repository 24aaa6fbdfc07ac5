#include "trainer/training_rays.h"

#include <cmath>
#include <numbers>

#include "engine/core/error.h"

namespace nbvh {

bool clip_line_to_box(const glm::vec3& origin, const glm::vec3& dir, const Aabb& box, float& t_entry, float& t_exit) {
    if (box.empty()) return false;
    float t0 = -NB_INF, t1 = NB_INF;
    for (int a = 0; a < 3; ++a) {
        const float o = origin[a], d = dir[a], lo = box.lo[a], hi = box.hi[a];
        if (!std::isfinite(lo) || !std::isfinite(hi)) return false;
        if (d == 0.0f) {
            // Parallel to this slab: inside (faces included) or a miss; no 0 * inf.
            if (o < lo || o > hi) return false;
            continue;
        }
        const float inv = 1.0f / d;
        float ta = (lo - o) * inv, tb = (hi - o) * inv;
        if (ta > tb) std::swap(ta, tb);
        t0 = ta > t0 ? ta : t0;
        t1 = tb < t1 ? tb : t1;
    }
    if (!(t0 <= t1) || !std::isfinite(t0) || !std::isfinite(t1)) return false;
    t_entry = t0;
    t_exit = t1;
    return true;
}

Aabb dilate_box(const Aabb& box, float dilation) {
    const glm::vec3 c = box.center();
    const glm::vec3 half = 0.5f * (box.hi - box.lo) * (1.0f + dilation);
    return Aabb{c - half, c + half};
}

glm::vec3 uniform_sphere_direction(float u1, float u2) {
    const float phi = 2.0f * std::numbers::pi_v<float> * u1;
    const float cos_theta = 2.0f * u2 - 1.0f;
    const float sin_theta = std::sqrt(std::max(0.0f, 1.0f - cos_theta * cos_theta));
    return glm::vec3(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta);
}

void TrainingCut::assign(std::span<const uint32_t> leaf_nodes, size_t base_node_count) {
    leaves.assign(leaf_nodes.begin(), leaf_nodes.end());
    leaf_of_base_node.assign(base_node_count, -1);
    for (size_t i = 0; i < leaves.size(); ++i) {
        NBVH_CHECK(leaves[i] < base_node_count);
        leaf_of_base_node[leaves[i]] = int32_t(i);
    }
    keep_probability.assign(leaves.size(), 1.0f);
}

FirstLeaf first_leaf_of_cut(const Bvh& base, std::span<const Aabb> node_boxes, const TrainingCut& cut,
                            const glm::vec3& origin, const glm::vec3& dir, float dilation, float min_exit,
                            uint32_t root) {
    FirstLeaf best;
    if (base.nodes.empty()) return best;
    float best_entry = NB_INF;
    struct Entry {
        uint32_t node;
        float t_entry;
    };
    Entry stack[NB_BVH_MAX_DEPTH * 2 + 2];
    int top = 0;
    float t0, t1;
    NBVH_CHECK(root < base.nodes.size());
    if (!clip_line_to_box(origin, dir, dilate_box(node_boxes[root], dilation), t0, t1) || t1 <= min_exit) return best;
    stack[top++] = {root, t0};
    while (top > 0) {
        const Entry e = stack[--top];
        if (e.t_entry >= best_entry) continue; // an earlier leaf was already found
        const int32_t slot = cut.leaf_of_base_node[e.node];
        if (slot >= 0) {
            float a, b;
            clip_line_to_box(origin, dir, dilate_box(node_boxes[e.node], dilation), a, b);
            best = FirstLeaf{slot, a, b};
            best_entry = e.t_entry;
            continue;
        }
        const BvhNode& n = base.nodes[e.node];
        if (n.is_leaf()) continue; // below no cut leaf: cannot happen for a valid cut
        Entry kids[2];
        int count = 0;
        for (uint32_t child : {n.left, n.right}) {
            if (child == BVH_INVALID) continue;
            if (clip_line_to_box(origin, dir, dilate_box(node_boxes[child], dilation), t0, t1) && t1 > min_exit &&
                t0 < best_entry)
                kids[count++] = {child, t0};
        }
        if (count == 2 && kids[0].t_entry < kids[1].t_entry) std::swap(kids[0], kids[1]);
        NBVH_CHECK(top + count <= int(std::size(stack)));
        for (int i = 0; i < count; ++i) stack[top++] = kids[i]; // nearer child popped first
    }
    return best;
}

} // namespace nbvh
