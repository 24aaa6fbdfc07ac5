// Collapse of the binary BVH into the 4-wide quantized layout, and its CPU traversal (wide_bvh.h).
#include "engine/bvh/wide_bvh.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "engine/bvh/aabb_ops.h"
#include "engine/core/error.h"
#include "shaders/shared/intersect.h"

namespace nbvh {
namespace {

uint32_t leaf_ref(const BvhNode& n) {
    NBVH_CHECK(n.count >= 1 && n.count <= NB_LEAF_MAX_COUNT && n.first <= NB_LEAF_FIRST_MASK);
    return nb_make_leaf(n.first, n.count);
}

// The quantization step of one axis: the smallest power of two with 255 * step >= extent (so every
// child plane is reachable from the origin with q <= 255), at least 2^-126 (a normal float, so that
// q * step stays exact).
float axis_step(float lo, float hi) {
    const double extent = double(hi) - double(lo);
    if (!(extent <= 1e37)) throw Error("BVH bounds too wide to quantize: extent " + std::to_string(extent));
    int e = -126;
    if (extent > 0.0) std::frexp(extent / 255.0, &e); // extent / 255 = m 2^e with m < 1, so 2^e > it
    return std::ldexp(1.0f, std::max(e, -126));
}

// The decoded plane, exactly as nb_wide_child_bounds computes it (the product is exact).
float decode(float origin, float step, uint32_t q) { return origin + float(q) * step; }

// Quantizes [lo, hi] outward: decode(q_lo) <= lo and decode(q_hi) >= hi. Starts from the rounded
// estimate and steps until the float expression itself satisfies the bound (rounding of the addition
// is monotonic, and decode(0) = origin <= lo, decode(255) >= origin + extent >= hi).
void quantize(float origin, float step, float lo, float hi, uint32_t& q_lo, uint32_t& q_hi) {
    q_lo = uint32_t(std::clamp(std::floor((double(lo) - origin) / step), 0.0, 255.0));
    while (q_lo > 0 && decode(origin, step, q_lo) > lo) --q_lo;
    q_hi = uint32_t(std::clamp(std::ceil((double(hi) - origin) / step), 0.0, 255.0));
    while (q_hi < 255 && decode(origin, step, q_hi) < hi) ++q_hi;
    NBVH_CHECK(decode(origin, step, q_lo) <= lo && decode(origin, step, q_hi) >= hi);
}

struct WideKids {
    std::array<uint32_t, NB_WIDE_ARITY> node{}; // binary node ids
    uint32_t count = 0;
};

WideKids collapse(const Bvh& bvh, uint32_t b) {
    WideKids k;
    const BvhNode& n = bvh.nodes[b];
    if (n.is_leaf()) { // only the root of a one-leaf tree
        k.node[k.count++] = b;
        return k;
    }
    k.node[k.count++] = n.left;
    k.node[k.count++] = n.right;
    while (k.count < NB_WIDE_ARITY) {
        int best = -1;
        double best_area = -1.0;
        for (uint32_t i = 0; i < k.count; ++i) {
            const BvhNode& c = bvh.nodes[k.node[i]];
            if (c.is_leaf()) continue;
            const double a = half_area(c.bounds) + 1e-30 * half_perimeter(c.bounds);
            if (a > best_area) best_area = a, best = int(i);
        }
        if (best < 0) break;
        const BvhNode& c = bvh.nodes[k.node[best]];
        k.node[best] = c.left;
        k.node[k.count++] = c.right;
    }
    return k;
}

GpuWideNode empty_node() {
    GpuWideNode g{};
    g.origin = glm::vec3(0.0f);
    g.scale = glm::vec3(1.0f);
    g.child0 = g.child1 = g.child2 = g.child3 = NB_CHILD_NONE;
    return g;
}

void set_child(GpuWideNode& g, uint32_t i, uint32_t ref, const uint32_t q_lo[3], const uint32_t q_hi[3]) {
    uint32_t* refs[NB_WIDE_ARITY] = {&g.child0, &g.child1, &g.child2, &g.child3};
    *refs[i] = ref;
    const uint32_t shift = 8u * i;
    g.qlo_x |= q_lo[0] << shift, g.qlo_y |= q_lo[1] << shift, g.qlo_z |= q_lo[2] << shift;
    g.qhi_x |= q_hi[0] << shift, g.qhi_y |= q_hi[1] << shift, g.qhi_z |= q_hi[2] << shift;
}

} // namespace

std::vector<GpuWideNode> to_wide_layout(const Bvh& bvh, std::vector<WideChildBounds>* exact) {
    std::vector<GpuWideNode> out;
    if (exact) exact->clear();
    if (bvh.nodes.empty()) {
        out.push_back(empty_node());
        if (exact) exact->push_back(WideChildBounds{});
        return out;
    }
    // Pass 1: the wide nodes in depth-first order (first child's subtree right after its parent).
    std::vector<uint32_t> wide_of(bvh.nodes.size(), NB_CHILD_NONE);
    std::vector<WideKids> kids;
    std::vector<uint32_t> stack{0};
    while (!stack.empty()) {
        const uint32_t b = stack.back();
        stack.pop_back();
        wide_of[b] = uint32_t(kids.size());
        kids.push_back(collapse(bvh, b));
        const WideKids& k = kids.back();
        for (uint32_t i = k.count; i-- > 0;)
            if (k.node[i] != b && !bvh.nodes[k.node[i]].is_leaf()) stack.push_back(k.node[i]);
    }
    // Pass 2: references and quantized boxes.
    out.resize(kids.size());
    if (exact) exact->resize(kids.size());
    for (size_t w = 0; w < kids.size(); ++w) {
        const WideKids& k = kids[w];
        Aabb box;
        for (uint32_t i = 0; i < k.count; ++i) box.grow(bvh.nodes[k.node[i]].bounds);
        GpuWideNode& g = out[w];
        g = empty_node();
        g.origin = box.lo;
        g.scale = glm::vec3(axis_step(box.lo.x, box.hi.x), axis_step(box.lo.y, box.hi.y),
                            axis_step(box.lo.z, box.hi.z));
        for (uint32_t i = 0; i < k.count; ++i) {
            const BvhNode& c = bvh.nodes[k.node[i]];
            uint32_t q_lo[3], q_hi[3];
            for (int a = 0; a < 3; ++a) quantize(g.origin[a], g.scale[a], c.bounds.lo[a], c.bounds.hi[a], q_lo[a], q_hi[a]);
            set_child(g, i, c.is_leaf() ? leaf_ref(c) : wide_of[k.node[i]], q_lo, q_hi);
            if (exact) (*exact)[w][i] = c.bounds;
        }
    }
    return out;
}

bool wide_intersect(const std::vector<GpuWideNode>& nodes, const MeshBvh& mesh, const Ray& ray, float tmin,
                    float tmax, bool any, Hit& hit) {
    NbRayShear shear;
    if (nodes.empty() || mesh.triangle_count() == 0 || !nb_ray_shear(ray.dir, shear)) return false;
    const glm::vec3 inv_dir = nb_safe_inv_dir(ray.dir);
    const glm::vec3* v = mesh.vertices.data();
    bool found = false, done = false;
    float t_min = tmin, t_max = tmax; // NB_TRAVERSE_WIDE culls by these; the leaf narrows t_max
    auto leaf = [&](uint32_t first, uint32_t count) {
        for (uint32_t k = first; k < first + count; ++k) {
            NBVH_CHECK(k < mesh.triangle_count());
            float t, u, w;
            if (!nb_intersect_triangle_sheared(ray.org, shear, v[3 * k], v[3 * k + 1], v[3 * k + 2], t_min, t_max, t, u, w))
                continue;
            if (!mesh.single_sided.empty() && mesh.single_sided[k] &&
                nb_back_facing(v[3 * k], v[3 * k + 1], v[3 * k + 2], ray.dir))
                continue;
            found = true;
            t_max = t;
            hit = Hit{t, mesh.bvh.prim_indices[k], u, w};
            if (any) {
                done = true;
                return;
            }
        }
    };
    NB_TRAVERSE_WIDE(nodes, 0u, ray.org, inv_dir, t_min, t_max, done, leaf)
    return found;
}

} // namespace nbvh
