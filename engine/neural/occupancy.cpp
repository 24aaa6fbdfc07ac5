#include "engine/neural/occupancy.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <future>
#include <thread>

namespace nbvh {
namespace {

using glm::dvec3;

// Separating-axis test of one axis: the triangle's projection [min, max] against the box's radius r.
bool separated(double p0, double p1, double p2, double r) {
    return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
}

struct Builder {
    std::span<const NbvhNode> nodes;
    const Mesh& mesh;
    std::vector<uint32_t>& words;

    dvec3 vertex(uint32_t tri, int k) const { return dvec3(mesh.positions[mesh.indices[3 * size_t(tri) + size_t(k)]]); }

    // The node box grown by the marking margin of a cell (and by a few ulps of its coordinates, so
    // flat boxes have a positive thickness).
    void grown_box(const Aabb& b, dvec3& lo, dvec3& hi) const {
        const dvec3 l(b.lo), h(b.hi);
        const dvec3 m = glm::max(glm::abs(l), glm::abs(h));
        const double ulps = std::max(1e-6 * std::max({m.x, m.y, m.z}), 1e-30);
        const dvec3 grow = (h - l) * (double(NB_OCC_MARK_MARGIN) / double(NB_OCC_RES)) + dvec3(ulps);
        lo = l - grow;
        hi = h + grow;
    }

    bool tri_box_bounds_overlap(uint32_t t, const dvec3& lo, const dvec3& hi) const {
        const dvec3 a = vertex(t, 0), b = vertex(t, 1), c = vertex(t, 2);
        const dvec3 tl = glm::min(a, glm::min(b, c)), th = glm::max(a, glm::max(b, c));
        return tl.x <= hi.x && th.x >= lo.x && tl.y <= hi.y && th.y >= lo.y && tl.z <= hi.z && th.z >= lo.z;
    }

    void mark(uint32_t node, std::span<const uint32_t> tris) {
        const Aabb& b = nodes[node].bounds;
        const dvec3 l(b.lo), e = dvec3(b.hi) - dvec3(b.lo);
        const dvec3 cell = e / double(NB_OCC_RES);
        dvec3 glo, ghi;
        grown_box(b, glo, ghi);
        const dvec3 margin = l - glo; // per axis: the growth of the box, also that of each cell
        uint32_t* w = words.data() + size_t(node) * NB_OCC_WORDS;
        auto cell_range = [&](double v0, double v1, int axis, int& c0, int& c1) {
            if (!(e[axis] > 0.0)) { c0 = c1 = 0; return; }
            const double g0 = (v0 - margin[axis] - l[axis]) / cell[axis], g1 = (v1 + margin[axis] - l[axis]) / cell[axis];
            c0 = int(std::clamp(std::floor(g0), 0.0, double(NB_OCC_RES) - 1.0));
            c1 = int(std::clamp(std::floor(g1), 0.0, double(NB_OCC_RES) - 1.0));
        };
        for (uint32_t t : tris) {
            const dvec3 a = vertex(t, 0), bb = vertex(t, 1), c = vertex(t, 2);
            const dvec3 tl = glm::min(a, glm::min(bb, c)), th = glm::max(a, glm::max(bb, c));
            int x0, x1, y0, y1, z0, z1;
            cell_range(tl.x, th.x, 0, x0, x1);
            cell_range(tl.y, th.y, 1, y0, y1);
            cell_range(tl.z, th.z, 2, z0, z1);
            const bool one = x0 == x1 && y0 == y1 && z0 == z1; // the bounds test already holds
            for (int z = z0; z <= z1; ++z)
                for (int y = y0; y <= y1; ++y)
                    for (int x = x0; x <= x1; ++x) {
                        const uint32_t bit = nb_occ_bit(uint32_t(x), uint32_t(y), uint32_t(z));
                        if (nb_occ_is_set(w[bit >> 5], bit)) continue;
                        if (!one) {
                            const dvec3 clo = l + dvec3(x, y, z) * cell - margin;
                            const dvec3 chi = l + dvec3(x + 1, y + 1, z + 1) * cell + margin;
                            if (!triangle_box_overlap((clo + chi) * 0.5, (chi - clo) * 0.5, a, bb, c)) continue;
                        }
                        w[bit >> 5] |= 1u << (bit & 31u);
                    }
        }
    }

    // Marks `node` (when used) and recurses with the triangles that may touch each child.
    void visit(uint32_t node, std::span<const uint32_t> tris, uint32_t depth, uint32_t parallel_depth) {
        const NbvhNode& n = nodes[node];
        if (occupancy_node_used(n)) mark(node, tris);
        else std::fill_n(words.begin() + ptrdiff_t(size_t(node) * NB_OCC_WORDS), NB_OCC_WORDS, ~0u);
        if (!n.has_children()) return;
        auto child = [&](uint32_t c) {
            dvec3 lo, hi;
            grown_box(nodes[c].bounds, lo, hi);
            std::vector<uint32_t> sub;
            for (uint32_t t : tris)
                if (tri_box_bounds_overlap(t, lo, hi)) sub.push_back(t);
            visit(c, sub, depth + 1, parallel_depth);
        };
        if (depth < parallel_depth) {
            auto left = std::async(std::launch::async, [&] { child(n.left); });
            child(n.left + 1);
            left.get();
        } else {
            child(n.left);
            child(n.left + 1);
        }
    }
};

} // namespace

bool triangle_box_overlap(const dvec3& c, const dvec3& h, const dvec3& a, const dvec3& b, const dvec3& cc) {
    const dvec3 v0 = a - c, v1 = b - c, v2 = cc - c;
    // Box axes.
    for (int k = 0; k < 3; ++k)
        if (separated(v0[k], v1[k], v2[k], h[k])) return false;
    const dvec3 e[3] = {v1 - v0, v2 - v1, v0 - v2};
    // Triangle normal.
    const dvec3 nrm = glm::cross(e[0], e[1]);
    const double r = h.x * std::abs(nrm.x) + h.y * std::abs(nrm.y) + h.z * std::abs(nrm.z);
    const double d = glm::dot(nrm, v0);
    if (d > r || d < -r) return false;
    // The nine edge x axis products.
    for (const dvec3& f : e)
        for (int k = 0; k < 3; ++k) {
            dvec3 axis(0.0);
            axis[(k + 1) % 3] = -f[(k + 2) % 3];
            axis[(k + 2) % 3] = f[(k + 1) % 3]; // unit axis k x f
            const double rr = h.x * std::abs(axis.x) + h.y * std::abs(axis.y) + h.z * std::abs(axis.z);
            if (separated(glm::dot(v0, axis), glm::dot(v1, axis), glm::dot(v2, axis), rr)) return false;
        }
    return true;
}

std::vector<uint32_t> build_occupancy(std::span<const NbvhNode> nodes, const Mesh& mesh, uint32_t threads) {
    std::vector<uint32_t> words(nodes.size() * NB_OCC_WORDS, 0u);
    if (nodes.empty()) return words;
    if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
    Builder b{nodes, mesh, words};
    dvec3 lo, hi;
    b.grown_box(nodes[0].bounds, lo, hi);
    std::vector<uint32_t> tris;
    for (uint32_t t = 0; t < mesh.triangle_count(); ++t)
        if (b.tri_box_bounds_overlap(t, lo, hi)) tris.push_back(t);
    // Subtrees below depth log2(threads) + 1 run in sequence (nodes are disjoint: no two tasks share a word).
    const uint32_t parallel_depth = uint32_t(std::bit_width(threads));
    b.visit(0, tris, 0, parallel_depth);
    return words;
}

bool occupancy_segment_occupied(const uint32_t* words, const glm::vec3& org, const glm::vec3& dir, const Aabb& box,
                                float t0, float t1) {
    GpuOccWalk w = nb_occ_walk_begin(org, dir, box.lo, box.hi, t0, t1);
    if (!w.exact) return true;
    do {
        const uint32_t bit = nb_occ_walk_bit(w);
        if (nb_occ_is_set(words[bit >> 5], bit)) return true;
    } while (nb_occ_walk_next(w));
    return false;
}

double occupancy_fraction(const NbvhTree& tree, std::span<const uint32_t> words, uint32_t lod) {
    if (words.size() != size_t(tree.node_count()) * NB_OCC_WORDS) return 1.0;
    uint64_t set = 0, all = 0;
    for (uint32_t i : tree.leaves_at(lod)) {
        for (uint32_t k = 0; k < NB_OCC_WORDS; ++k) set += uint64_t(std::popcount(words[size_t(i) * NB_OCC_WORDS + k]));
        all += NB_OCC_WORDS * 32u;
    }
    return all ? double(set) / double(all) : 1.0;
}

} // namespace nbvh
