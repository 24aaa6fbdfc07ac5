#include "trainer/cuda/cut_tree.h"

#include <stdexcept>
#include <string>

namespace nbvh::cuda {

void append_cut_tree(const std::vector<float>& boxes, const std::vector<uint32_t>& children,
                     const std::vector<int32_t>& leaf_of_base_node, const std::vector<uint32_t>& part_roots,
                     std::vector<CutNode>& nodes, std::vector<uint32_t>& roots) {
    const size_t base = boxes.size() / 6;
    if (children.size() != 2 * base || leaf_of_base_node.size() != base)
        throw std::invalid_argument("cut tree: " + std::to_string(base) + " base nodes but " +
                                    std::to_string(children.size()) + " children and " +
                                    std::to_string(leaf_of_base_node.size()) + " leaf slots");
    // Depth-first, left child right after its parent. Each entry: base node, and where to write its
    // compact index (the parent's child field; kCutNone for a part root, whose index goes to `roots`).
    struct Entry { uint32_t node; size_t parent; int side; };
    std::vector<Entry> stack;
    const size_t limit = nodes.size() + base * part_roots.size(); // a tree visits each node once per part
    for (const uint32_t root : part_roots) {
        if (root >= base) {
            if (base == 0) { roots.push_back(kCutNone); continue; }
            throw std::invalid_argument("cut tree: part root " + std::to_string(root) + " outside the base BVH");
        }
        roots.push_back(uint32_t(nodes.size()));
        stack.push_back({root, 0, -1});
        while (!stack.empty()) {
            const Entry e = stack.back();
            stack.pop_back();
            if (nodes.size() >= limit) throw std::invalid_argument("cut tree: the base BVH is not a tree");
            CutNode n{};
            box_centre_half(&boxes[6 * size_t(e.node)], &boxes[6 * size_t(e.node) + 3], n.centre, n.half);
            const CutBox kind = classify_cut_box(n.centre, n.half);
            if (kind == CutBox::out_of_range)
                throw std::invalid_argument("cut tree: the box of base node " + std::to_string(e.node) +
                                            " reaches beyond 1e37");
            if (kind == CutBox::never_crossed) { // no ray enters it: left out with its subtree
                if (e.side < 0) roots.back() = kCutNone;
                continue;
            }
            const uint32_t me = uint32_t(nodes.size());
            if (e.side == 0) nodes[e.parent].left = me;
            if (e.side == 1) nodes[e.parent].right = me;
            n.left = n.right = kCutNone;
            const int32_t slot = leaf_of_base_node[e.node];
            if (slot >= 0) {
                n.left = uint32_t(slot);
                n.right = kCutLeafTag;
                nodes.push_back(n);
                continue;
            }
            nodes.push_back(n);
            const uint32_t l = children[2 * size_t(e.node)], r = children[2 * size_t(e.node) + 1];
            if (r != kCutNone) {
                if (r >= base) throw std::invalid_argument("cut tree: child outside the base BVH");
                stack.push_back({r, me, 1});
            }
            if (l != kCutNone) {
                if (l >= base) throw std::invalid_argument("cut tree: child outside the base BVH");
                stack.push_back({l, me, 0});
            }
        }
    }
}

} // namespace nbvh::cuda
