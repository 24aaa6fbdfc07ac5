// join_bvhs (bvh.h): the parts' trees under a SAH tree over their root boxes.
#include <algorithm>

#include "engine/bvh/bvh.h"
#include "engine/core/error.h"
#include "engine/core/log.h"

namespace nbvh {

namespace {

struct Joiner {
    std::span<const Bvh> parts;
    std::span<const uint32_t> offsets;
    const Bvh& top;
    Bvh out;
    std::vector<uint32_t> roots;

    // Fills out.nodes[slot] with top node `t` (and everything below it).
    void emit(uint32_t t, uint32_t slot, uint32_t parent, uint32_t depth) {
        const BvhNode& tn = top.nodes[t];
        if (!tn.is_leaf()) {
            const uint32_t kids = uint32_t(out.nodes.size());
            out.nodes.resize(out.nodes.size() + 2);
            BvhNode& n = out.nodes[slot];
            n.bounds = tn.bounds;
            n.left = kids;
            n.right = kids + 1;
            n.parent = parent;
            n.depth = depth;
            n.count = 0;
            emit(tn.left, kids, slot, depth + 1);
            emit(tn.right, kids + 1, slot, depth + 1);
            return;
        }
        NBVH_CHECK(tn.count == 1);
        const uint32_t p = top.prim_indices[tn.first];
        const Bvh& part = parts[p];
        roots[p] = slot;
        // Part node 0 goes to `slot`, node i >= 1 to base + i - 1: children stay adjacent and after
        // their parent (base > slot).
        const uint32_t base = uint32_t(out.nodes.size());
        const uint32_t prim_base = uint32_t(out.prim_indices.size());
        for (uint32_t id : part.prim_indices) out.prim_indices.push_back(id + offsets[p]);
        out.nodes.resize(out.nodes.size() + part.nodes.size() - 1);
        auto map = [&](uint32_t i) { return i == 0 ? slot : base + i - 1; };
        for (uint32_t i = 0; i < part.nodes.size(); ++i) {
            BvhNode n = part.nodes[i];
            if (!n.is_leaf()) {
                n.left = map(n.left);
                n.right = map(n.right);
            } else {
                n.first += prim_base;
            }
            n.parent = i == 0 ? parent : map(n.parent);
            n.depth = part.nodes[i].depth + depth;
            if (n.depth >= NB_BVH_MAX_DEPTH)
                throw Error(strfmt("the joined BVH of %zu parts is deeper than %u levels", parts.size(), NB_BVH_MAX_DEPTH));
            out.nodes[map(i)] = n;
        }
    }
};

} // namespace

Bvh join_bvhs(std::span<const Bvh> parts, std::span<const uint32_t> prim_offsets, std::vector<uint32_t>* part_roots) {
    NBVH_CHECK(parts.size() == prim_offsets.size());
    if (parts.empty()) throw Error("join_bvhs: no parts");
    std::vector<Aabb> boxes;
    for (const Bvh& b : parts) {
        if (b.empty()) throw Error("join_bvhs: a part has no primitives");
        boxes.push_back(b.nodes[0].bounds);
    }
    BvhBuildOptions opt;
    opt.max_leaf_size = 1;
    const Bvh top = build_bvh(boxes, opt);
    if (top.prim_indices.size() != parts.size()) throw Error("join_bvhs: a part has a non-finite or empty box");
    Joiner j{parts, prim_offsets, top, {}, std::vector<uint32_t>(parts.size(), BVH_INVALID)};
    j.out.nodes.resize(1);
    j.emit(0, 0, BVH_INVALID, 0);
    if (part_roots) *part_roots = std::move(j.roots);
    return std::move(j.out);
}

} // namespace nbvh
