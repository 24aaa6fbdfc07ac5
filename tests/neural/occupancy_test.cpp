// Occupancy masks (shaders/shared/neural_occupancy.h, engine/neural/occupancy.h): the cell walk against a
// dense sampling of the segment (random, tiny, huge, far and flat boxes), hand-made rays (axis-parallel,
// in cell-boundary planes, zero components, through cell corners), NaN/inf and rounding fall-backs, the
// double-precision triangle-box test, and build_occupancy: exact cells, unused nodes, thread counts and
// conservativeness (no ray with a true hit in a node's box segment is ever culled).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "engine/neural/occupancy.h"
#include "shaders/shared/neural_gpu.h"

namespace nbvh {
namespace {

using glm::dvec3;
constexpr int R = int(NB_OCC_RES);
constexpr double kInf = std::numeric_limits<double>::infinity();

std::vector<ivec3> walk_cells(vec3 org, vec3 dir, vec3 lo, vec3 hi, float t0, float t1, bool* exact = nullptr) {
    GpuOccWalk w = nb_occ_walk_begin(org, dir, lo, hi, t0, t1);
    if (exact) *exact = w.exact;
    std::vector<ivec3> cells;
    do cells.push_back(w.cell);
    while (nb_occ_walk_next(w) && cells.size() < 64); // 64: a runaway walk fails the size checks below
    return cells;
}

std::string str(vec3 v) {
    char b[96];
    std::snprintf(b, sizeof b, "(%.9g, %.9g, %.9g)", double(v.x), double(v.y), double(v.z));
    return b;
}

// Slab interval of a ray with a box in double precision (a zero direction component: inside or not).
bool slab(dvec3 o, dvec3 d, dvec3 lo, dvec3 hi, double& te, double& tx) {
    te = -kInf, tx = kInf;
    for (int k = 0; k < 3; ++k) {
        if (d[k] == 0.0) { if (o[k] < lo[k] || o[k] > hi[k]) return false; continue; }
        double a = (lo[k] - o[k]) / d[k], b = (hi[k] - o[k]) / d[k];
        if (a > b) std::swap(a, b);
        te = std::max(te, a), tx = std::min(tx, b);
    }
    return te <= tx;
}

struct WalkStats { int exact = 0, inexact = 0; long points = 0; };

// Test 1's check of one segment; "" when it passes. Only exact walks are checked. The reference is the
// segment in double precision: every sampled point's cell (clamped to the grid) must be visited, except
// within `margin` of an inner cell boundary, where either neighbour is acceptable: margin = 1e-3 cell,
// or twice the walk's own rounding bound (at most 1/32 cell, NB_OCC_MARK_MARGIN, which covers it).
std::string check_walk(vec3 org, vec3 dir, vec3 lo, vec3 hi, float t0, float t1, WalkStats& st) {
    bool exact = false;
    const std::vector<ivec3> cells = walk_cells(org, dir, lo, hi, t0, t1, &exact);
    if (!exact) { ++st.inexact; return ""; }
    ++st.exact;
    const std::string in = "org " + str(org) + " dir " + str(dir) + " lo " + str(lo) + " hi " + str(hi) + " t " +
                           std::to_string(t0) + ".." + std::to_string(t1) + ": ";
    const vec3 s = nb_occ_scale(lo, hi), d = dir * s;
    const vec3 err = (abs(org) + abs(dir) * std::max(std::abs(t0), std::abs(t1)) + abs(lo) + abs(hi)) * s * 4.0e-7f;
    const double margin = std::max(1e-3, 2.0 * double(std::max({err.x, err.y, err.z})));
    if (cells.size() > NB_OCC_MAX_STEPS) return in + "more than 22 cells";
    for (size_t i = 0; i < cells.size(); ++i) {
        for (int k = 0; k < 3; ++k)
            if (cells[i][k] < 0 || cells[i][k] >= (s[k] > 0.0f ? R : 1)) return in + "cell outside the grid";
        if (i == 0) continue;
        // In order along the ray: one axis per step, the way the direction points (so no cell twice).
        const ivec3 step = cells[i] - cells[i - 1];
        if (std::abs(step.x) + std::abs(step.y) + std::abs(step.z) != 1) return in + "not a single-axis step";
        for (int k = 0; k < 3; ++k)
            if (step[k] != 0 && (d[k] == 0.0f || step[k] != (d[k] > 0.0f ? 1 : -1))) return in + "step against the ray";
    }
    auto grid = [&](int k, double t) {
        return (double(org[k]) + double(dir[k]) * t - double(lo[k])) * R / (double(hi[k]) - double(lo[k]));
    };
    for (int i = 0; i < 4000; ++i) {
        const double t = double(t0) + (double(t1) - double(t0)) * i / 3999.0;
        ivec3 c(0);
        bool skip = false;
        for (int k = 0; k < 3 && !skip; ++k) {
            if (s[k] == 0.0f) continue;
            const double g = grid(k, t), r = std::round(g);
            skip = r >= 1.0 && r <= R - 1 && std::abs(g - r) < margin;
            c[k] = int(std::clamp(std::floor(g), 0.0, double(R - 1)));
        }
        if (skip) continue;
        ++st.points;
        if (std::find(cells.begin(), cells.end(), c) == cells.end())
            return in + "missed cell (" + std::to_string(c.x) + "," + std::to_string(c.y) + "," + std::to_string(c.z) +
                   ") at t " + std::to_string(t) + " (walk visited " + std::to_string(cells.size()) + " cells)";
    }
    // No visited cell lies off the segment (grown by the margin).
    for (const ivec3& c : cells) {
        double a = t0, b = t1;
        for (int k = 0; k < 3; ++k) {
            if (s[k] == 0.0f) continue;
            const double clo = c[k] == 0 ? -kInf : c[k] - margin, chi = c[k] == R - 1 ? kInf : c[k] + 1 + margin;
            const double g0 = grid(k, 0.0), dg = grid(k, 1.0) - g0;
            if (dg == 0.0) { if (g0 < clo || g0 > chi) a = kInf; continue; }
            double u = (clo - g0) / dg, v = (chi - g0) / dg;
            if (u > v) std::swap(u, v);
            a = std::max(a, u), b = std::min(b, v);
        }
        if (a > b + 1e-6 * std::max(std::abs(a), std::abs(b))) return in + "visited a cell off the segment";
    }
    return "";
}

TEST(Occupancy, WalkVisitsEveryCellOfTheSegment) {
    std::mt19937 rng(1234);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    const float sizes[] = {1.0e-4f, 1.0f, 1.0e4f};
    WalkStats st;
    std::string first;
    int failures = 0, segments = 0;
    auto check = [&](vec3 o, vec3 d, vec3 lo, vec3 hi, float t0, float t1) {
        ++segments;
        const std::string f = check_walk(o, d, lo, hi, t0, t1, st);
        if (!f.empty() && failures++ == 0) first = f;
    };
    for (int b = 0; b < 900; ++b) {
        const float size = sizes[b % 3];
        const int place = (b / 3) % 3; // near the origin, 20 sizes away, 3e4 away (tiny boxes there: inexact)
        const vec3 off = place == 0 ? vec3(-0.5f * size) : place == 1 ? vec3(20.0f * size, -13.0f * size, 7.0f * size)
                                                                      : vec3(3.0e4f, -2.0e4f, 3.0e4f);
        vec3 ext = size * vec3(0.3f + 2.7f * u01(rng), 0.3f + 2.7f * u01(rng), 0.3f + 2.7f * u01(rng));
        const int flat = b % 5 == 3 ? 1 : b % 5 == 4 ? 2 : 0; // one or two zero extents
        for (int k = 0; k < flat; ++k) ext[(b + k) % 3] = 0.0f;
        const vec3 lo = off, hi = off + ext;
        auto inside = [&] { return lo + ext * vec3(u01(rng), u01(rng), u01(rng)); };
        auto in_plane = [&](vec3& o, vec3& d) { // rays of a flat box lie in its plane
            for (int k = 0; k < 3; ++k)
                if (ext[k] == 0.0f) o[k] = lo[k], d[k] = 0.0f;
        };
        auto clip = [&](vec3 o, vec3 d, float& t0, float& t1) {
            double te, tx;
            if (!slab(dvec3(o), dvec3(d), dvec3(lo), dvec3(hi), te, tx)) return false;
            t0 = float(te), t1 = float(tx);
            return t0 <= t1;
        };
        // Origin inside, the segment to the exit; directions of any length.
        vec3 o = inside(), d = vec3(u01(rng) - 0.5f, u01(rng) - 0.5f, u01(rng) - 0.5f) * std::exp2(float(b % 7) - 3.0f);
        in_plane(o, d);
        float t0, t1;
        if (clip(o, d, t0, t1) && d != vec3(0.0f)) check(o, d, lo, hi, 0.0f, t1);
        // Origin outside (3 sizes away), aimed into the box, clipped; a part inside; a point (t0 == t1).
        const float ang = 6.2831853f * u01(rng), zc = 2.0f * u01(rng) - 1.0f, rc = std::sqrt(1.0f - zc * zc);
        o = lo + 0.5f * ext + 3.0f * size * vec3(rc * std::cos(ang), rc * std::sin(ang), zc);
        d = inside() - o;
        in_plane(o, d);
        if (clip(o, d, t0, t1)) {
            check(o, d, lo, hi, t0, t1);
            float a = t0 + (t1 - t0) * u01(rng), c = t0 + (t1 - t0) * u01(rng);
            check(o, d, lo, hi, std::min(a, c), std::max(a, c));
            check(o, d, lo, hi, a, a);
            check(o, d, lo, hi, 0.0f, t1 + (t1 - t0)); // unclipped: from the origin to past the exit
            float le, lx; // the GPU's leaf interval (the box dilated by NB_LEAF_DILATION)
            if (nb_neural_leaf_interval(o, nb_safe_inv_dir(d), lo, hi, le, lx)) check(o, d, lo, hi, le, lx);
        }
        if (flat) { // a ray crossing a flat box meets it in one point
            const vec3 o2 = inside() + vec3(0.5f * size), d2 = inside() - o2;
            if (clip(o2, d2, t0, t1)) check(o2, d2, lo, hi, t0, t1);
        }
    }
    EXPECT_EQ(failures, 0) << failures << " of " << segments << " segments fail; first: " << first;
    std::printf("[ walk ] %d segments, %d exact, %d inexact, %ld points checked\n", segments, st.exact, st.inexact, st.points);
    EXPECT_GT(st.exact, 3000);
    EXPECT_GT(st.inexact, 100); // tiny boxes 3e4 away
    EXPECT_GT(st.points, 5000000);
}

TEST(Occupancy, WalkSpecialRays) {
    struct Case { vec3 org, dir, lo, hi; float t0, t1; ivec3 start, end; int count; }; // count 0: not checked
    const vec3 l0(0.0f), h1(1.0f), l2(-2.0f), h6(6.0f); // cells of 1/8 and of 1
    const Case cases[] = {
        {{-1, 0.3f, 0.7f}, {1, 0, 0}, l0, h1, 1, 2, {0, 2, 5}, {7, 2, 5}, 8},        // axis-parallel
        {{0.3f, 2, 0.7f}, {0, -1, 0}, l0, h1, 1, 2, {2, 7, 5}, {2, 0, 5}, 8},        // negative
        {{-1, 0.375f, 0.5f}, {1, 0, 0}, l0, h1, 1, 2, {0, 3, 4}, {7, 3, 4}, 8},      // in boundary planes
        {{2, 0.5f, 0.5f}, {-1, 0, 0}, l0, h1, 1, 2, {7, 4, 4}, {0, 4, 4}, 8},
        {{0.5f, -3, -2}, {0, 1, 0.5f}, l2, h6, 1, 9, {2, 0, 0}, {2, 7, 4}, 12},      // dir.x = 0, yz corners
        {{0, 0, 0}, {1, 1, 1}, l0, h1, 0, 1, {0, 0, 0}, {7, 7, 7}, 22},               // through every corner
        {{1, 1, 1}, {-1, -1, -1}, l0, h1, 0, 1, {7, 7, 7}, {0, 0, 0}, 22},
        {{-2, -2, -2}, {3, 3, 3}, l2, h6, 0, 8.0f / 3.0f, {0, 0, 0}, {7, 7, 7}, 22},
        {{-1, -1, 0.55f}, {1, 1, 0}, l0, h1, 1, 2, {0, 0, 4}, {7, 7, 4}, 15},        // xy corners
        {{-0.5f, 0, 0.3f}, {1, 0, 0.2f}, l0, h1, 0.5f, 1.5f, {0, 0, 3}, {7, 0, 4}, 9}, // in the face y = lo
        {{-1, 0.3f, 0.3f}, {1, 1e-40f, -1e-40f}, l0, h1, 1, 2, {0, 2, 2}, {7, 2, 2}, 8}, // denormal components
        {{0.5f, 0.5f, 0.5f}, {-1, -1, -1}, l0, h1, 0, 0, {4, 4, 4}, {3, 3, 3}, 4},   // a point on a corner
        {{0.3f, 0.6f, 0.2f}, {0, 0, 0}, l0, h1, 0, 5, {2, 4, 1}, {2, 4, 1}, 1},      // zero direction
    };
    WalkStats st;
    for (const Case& c : cases) {
        bool exact = false;
        const std::vector<ivec3> cells = walk_cells(c.org, c.dir, c.lo, c.hi, c.t0, c.t1, &exact);
        SCOPED_TRACE("org " + str(c.org) + " dir " + str(c.dir));
        ASSERT_TRUE(exact);
        EXPECT_EQ(cells.front(), c.start);
        EXPECT_EQ(cells.back(), c.end);
        if (c.count) { EXPECT_EQ(int(cells.size()), c.count); }
        EXPECT_EQ(check_walk(c.org, c.dir, c.lo, c.hi, c.t0, c.t1, st), "");
    }
}

TEST(Occupancy, WalkNotExactOnNanInfAndRounding) {
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    const vec3 lo(0.0f), hi(1.0f), o(-1.0f, 0.5f, 0.5f), d(1.0f, 0.0f, 0.0f);
    struct Case { vec3 org, dir, lo, hi; float t0, t1; };
    const vec3 far_lo(1.0e3f), far_hi = far_lo + vec3(1.0e-3f); // 16 float steps wide
    const Case cases[] = {
        {{nan, 0.5f, 0.5f}, d, lo, hi, 1, 2}, {o, {1, nan, 0}, lo, hi, 1, 2}, {o, d, lo, hi, 1, inf},
        {o, d, lo, hi, 1, NB_INF}, {o, d, lo, hi, -inf, 2}, {o, d, lo, hi, nan, 2}, {o, d, lo, hi, 2, 1},
        {{-inf, 0.5f, 0.5f}, d, lo, hi, 1, 2}, {o, {inf, 0, 0}, lo, hi, 1, 2}, {{0.5f, inf, 0.5f}, d, {0, 0.5f, 0}, {1, 0.5f, 1}, 1, 2},
        {far_lo - vec3(1.0f, 0, 0), d, far_lo, far_hi, 1.0f, 1.0001f},           // tiny box far away
        {{-1.0e4f, 5e-5f, 5e-5f}, d, lo, vec3(1.0e-4f), 1.0e4f, 1.0001e4f},     // tiny box, far origin
        {{3.0e4f - 1, 3.0e4f, 3.0e4f}, d, vec3(3.0e4f), vec3(3.0e4f + 1), 1, 2}, // unit box 3e4 away
    };
    for (const Case& c : cases) {
        bool exact = true;
        const std::vector<ivec3> cells = walk_cells(c.org, c.dir, c.lo, c.hi, c.t0, c.t1, &exact);
        EXPECT_FALSE(exact) << "org " << str(c.org) << " dir " << str(c.dir) << " t " << c.t0 << ".." << c.t1;
        EXPECT_LE(cells.size(), size_t(NB_OCC_MAX_STEPS) + 1); // terminates, no garbage cells
        for (const ivec3& cell : cells) EXPECT_TRUE(cell == glm::clamp(cell, ivec3(0), ivec3(R - 1)));
        EXPECT_TRUE(occupancy_segment_occupied(std::vector<uint32_t>(NB_OCC_WORDS, 0u).data(), c.org, c.dir,
                                               Aabb{c.lo, c.hi}, c.t0, c.t1));
    }
}

// Reference: the triangle clipped by the box's six planes (Sutherland-Hodgman) is not empty.
bool clip_overlap(dvec3 c, dvec3 h, dvec3 a, dvec3 b, dvec3 e) {
    std::vector<dvec3> poly{a, b, e};
    for (int k = 0; k < 3; ++k)
        for (double sgn : {1.0, -1.0}) {
            std::vector<dvec3> out;
            auto in = [&](const dvec3& p) { return sgn * (p[k] - c[k]) <= h[k]; };
            for (size_t i = 0; i < poly.size(); ++i) {
                const dvec3 p = poly[i], q = poly[(i + 1) % poly.size()];
                if (in(p)) out.push_back(p);
                if (in(p) != in(q)) {
                    const double t = (c[k] + sgn * h[k] - p[k]) / (q[k] - p[k]);
                    out.push_back(p + (q - p) * t);
                }
            }
            poly.swap(out);
        }
    return !poly.empty();
}

TEST(Occupancy, TriangleBoxOverlap) {
    const dvec3 c(0.0), h(1.0);
    auto ov = [&](dvec3 a, dvec3 b, dvec3 e) { return triangle_box_overlap(c, h, a, b, e); };
    EXPECT_TRUE(ov({0.1, 0.1, 0.1}, {0.3, 0.1, 0.2}, {0.2, 0.4, -0.3}));   // inside
    EXPECT_FALSE(ov({5, 5, 5}, {6, 5, 5}, {5, 6, 5}));                     // far away
    EXPECT_TRUE(ov({-5, -5, 0}, {5, -5, 0}, {0, 5, 0}));                   // plane cut, no vertex inside
    EXPECT_TRUE(ov({-0.2, 0, 3}, {0.2, 0, 3}, {0, 0.1, -3}));             // sliver through two faces
    EXPECT_TRUE(ov({-0.5, -0.5, 1}, {3, 0, 1}, {0, 3, 1}));               // lying in the face z = 1
    EXPECT_TRUE(ov({1, 1, 1}, {3, 1, 2}, {1, 4, 3}));                     // touching a corner
    EXPECT_FALSE(ov({-0.5, -0.5, 1 + 1e-9}, {3, 0, 1 + 1e-9}, {0, 3, 1 + 1e-9}));
    // Bounds overlap the box, the plane cuts it, but x + y >= 2.2 > 2 on the triangle: only the edge
    // cross axis z x (-1, 1, 0) separates.
    EXPECT_FALSE(ov({1.6, 0.6, 0}, {0.6, 1.6, 0}, {5, 5, 3}));
    EXPECT_TRUE(ov({1.4, 0.5, 0}, {0.5, 1.4, 0}, {5, 5, 3}));             // x + y = 1.9: crosses the edge
    EXPECT_TRUE(ov({-3, -3, -3}, {0, 0, 0}, {3, 3, 3}));                   // collinear, through the box
    EXPECT_FALSE(ov({1.6, 0.6, 0}, {0.6, 1.6, 0}, {1.1, 1.1, 0}));        // collinear, beside the edge
    EXPECT_FALSE(ov({1.6, 0.6, 0}, {1.6, 0.6, 0}, {0.6, 1.6, 0}));        // repeated vertex, beside
    EXPECT_TRUE(ov({0.2, 0.3, 0.4}, {0.2, 0.3, 0.4}, {0.2, 0.3, 0.4}));   // a point inside
    EXPECT_FALSE(ov({1.2, 0.3, 0.4}, {1.2, 0.3, 0.4}, {1.2, 0.3, 0.4}));  // a point outside
    // Random triangles against the clipping reference (clear cases only: shrunk box hit, grown box missed).
    std::mt19937 rng(99);
    std::uniform_real_distribution<double> u(-2.0, 2.0);
    int checked = 0, wrong = 0;
    for (int i = 0; i < 20000; ++i) {
        const dvec3 hh(0.2 + std::abs(u(rng)) / 2, 0.2 + std::abs(u(rng)) / 2, 0.2 + std::abs(u(rng)) / 2);
        const dvec3 a(u(rng), u(rng), u(rng)), b = a + dvec3(u(rng), u(rng), u(rng)) * 0.5,
                    e = i % 10 == 0 ? b : a + dvec3(u(rng), u(rng), u(rng)) * 0.5;
        const bool got = triangle_box_overlap(c, hh, a, b, e);
        if (clip_overlap(c, hh * (1 - 1e-9), a, b, e)) ++checked, wrong += !got;
        else if (!clip_overlap(c, hh * (1 + 1e-9), a, b, e)) ++checked, wrong += got;
    }
    EXPECT_EQ(wrong, 0);
    EXPECT_GT(checked, 19000);
}

NbvhNode make_node(vec3 lo, vec3 hi, uint32_t left, uint8_t lod) {
    NbvhNode n;
    n.bounds = Aabb{lo, hi};
    n.left = left;
    n.lod = lod;
    n.final_leaf = left == NBVH_NO_CHILD;
    return n;
}

// Root [0,1]^3 split at x = 0.5 into two LoD-0 leaves.
std::vector<NbvhNode> two_leaves(uint8_t root_lod) {
    return {make_node(vec3(0.0f), vec3(1.0f), 1, root_lod), make_node(vec3(0.0f), vec3(0.5f, 1, 1), NBVH_NO_CHILD, 0),
            make_node(vec3(0.5f, 0, 0), vec3(1.0f), NBVH_NO_CHILD, 0)};
}

Mesh make_mesh(const std::vector<vec3>& corners) {
    Mesh m;
    m.positions = corners;
    for (uint32_t i = 0; i < corners.size(); ++i) m.indices.push_back(i);
    return m;
}

int popcount(const std::vector<uint32_t>& w, uint32_t node) {
    int n = 0;
    for (uint32_t k = 0; k < NB_OCC_WORDS; ++k) n += std::popcount(w[node * NB_OCC_WORDS + k]);
    return n;
}

bool bit(const std::vector<uint32_t>& w, uint32_t node, int x, int y, int z) {
    const uint32_t b = nb_occ_bit(uint32_t(x), uint32_t(y), uint32_t(z));
    return (w[node * NB_OCC_WORDS + (b >> 5)] >> (b & 31u)) & 1u;
}

// A 0.004-wide triangle about (0.15625, 0.4375, 0.5625): cell (2,3,4) of the left leaf, (1,3,4) of the root,
// at least 1/4 cell from any boundary.
Mesh one_triangle() {
    const vec3 p(0.15625f, 0.4375f, 0.5625f);
    return make_mesh({p + vec3(-0.002f, -0.002f, 0), p + vec3(0.002f, -0.002f, 0.001f), p + vec3(0, 0.002f, -0.001f)});
}

TEST(Occupancy, BuildSingleTriangleAndUnusedNodes) {
    const std::vector<NbvhNode> interior = two_leaves(NBVH_LOD_NONE);
    const std::vector<uint32_t> w = build_occupancy(interior, one_triangle(), 1);
    ASSERT_EQ(w.size(), 3 * NB_OCC_WORDS);
    EXPECT_EQ(popcount(w, 0), 512); // interior at every LoD: all ones
    EXPECT_EQ(popcount(w, 1), 1);
    EXPECT_TRUE(bit(w, 1, 2, 3, 4));
    EXPECT_EQ(popcount(w, 2), 0);
    const std::vector<uint32_t> w1 = build_occupancy(two_leaves(1), one_triangle(), 1); // root: a LoD-1 leaf
    EXPECT_EQ(popcount(w1, 0), 1);
    EXPECT_TRUE(bit(w1, 0, 1, 3, 4));
    EXPECT_EQ(popcount(w1, 1), 1);
    EXPECT_TRUE(bit(w1, 1, 2, 3, 4));
    EXPECT_EQ(popcount(w1, 2), 0);
}

TEST(Occupancy, BuildDiagonalTriangle) {
    const std::vector<NbvhNode> leaf{make_node(vec3(0.0f), vec3(1.0f), NBVH_NO_CHILD, 0)};
    // The points (t, t, z), z <= t: cells (i, i, k <= i), and neighbours touched at their edges.
    const std::vector<uint32_t> w = build_occupancy(leaf, make_mesh({vec3(0.0f), vec3(1, 1, 0), vec3(1.0f)}), 1);
    for (int i = 0; i < R; ++i) {
        EXPECT_TRUE(bit(w, 0, i, i, 0));
        EXPECT_TRUE(bit(w, 0, i, i, i));
        for (int z = 0; z < R; ++z) EXPECT_FALSE(bit(w, 0, 7, 0, z) || bit(w, 0, 0, 7, z)) << z;
    }
    EXPECT_FALSE(bit(w, 0, 0, 0, 7));
    EXPECT_FALSE(bit(w, 0, 3, 3, 5));
    EXPECT_LT(popcount(w, 0), 200);
}

double moller_trumbore(dvec3 o, dvec3 d, dvec3 a, dvec3 b, dvec3 c) { // t of the hit, or -1
    const dvec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
    const double det = glm::dot(e1, p);
    if (std::abs(det) < 1e-300) return -1.0;
    const dvec3 s = o - a, q = glm::cross(s, e1);
    const double u = glm::dot(s, p) / det, v = glm::dot(d, q) / det;
    if (u < 0.0 || v < 0.0 || u + v > 1.0) return -1.0;
    return glm::dot(e2, q) / det;
}

TEST(Occupancy, BuildIsConservativeAndCulls) {
    std::mt19937 rng(2024);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    std::vector<vec3> corners;
    for (int i = 0; i < 200; ++i) {
        const vec3 c(u01(rng), u01(rng), u01(rng));
        for (int k = 0; k < 3; ++k) corners.push_back(c + 0.03f * vec3(u01(rng) - 0.5f, u01(rng) - 0.5f, u01(rng) - 0.5f));
    }
    const Mesh mesh = make_mesh(corners);
    // Three levels of overlapping boxes (they need not bound the triangles): LoD 2, 1 and 0 leaves.
    const std::vector<NbvhNode> nodes{
        make_node({-0.05f, -0.05f, -0.05f}, {1.05f, 1.05f, 1.05f}, 1, 2),
        make_node({-0.02f, 0, 0}, {0.55f, 1, 1}, 3, 1), make_node({0.45f, 0, 0}, {1.03f, 1, 1}, 5, 1),
        make_node({0, 0, 0}, {0.55f, 0.6f, 1}, NBVH_NO_CHILD, 0), make_node({0, 0.4f, 0}, {0.5f, 1, 0.9f}, NBVH_NO_CHILD, 0),
        make_node({0.45f, 0, 0.1f}, {1, 0.5f, 1}, NBVH_NO_CHILD, 0), make_node({0.5f, 0.5f, 0}, {1, 1.02f, 1}, NBVH_NO_CHILD, 0)};
    const std::vector<uint32_t> w = build_occupancy(nodes, mesh, 1);
    EXPECT_EQ(w, build_occupancy(nodes, mesh, 4));
    int segments = 0, culled = 0, violations = 0;
    std::string first;
    for (int r = 0; r < 20000; ++r) {
        const vec3 target(1.2f * u01(rng) - 0.1f, 1.2f * u01(rng) - 0.1f, 1.2f * u01(rng) - 0.1f);
        const vec3 org = r % 2 ? vec3(u01(rng), u01(rng), u01(rng)) // inside, or 2 away
                               : vec3(0.5f) + 2.0f * normalize(vec3(u01(rng) - 0.5f, u01(rng) - 0.5f, u01(rng) - 0.5f));
        const vec3 dir = normalize(target - org);
        std::vector<double> hits;
        for (uint32_t t = 0; t < mesh.triangle_count(); ++t) {
            const double th = moller_trumbore(dvec3(org), dvec3(dir), dvec3(corners[3 * t]), dvec3(corners[3 * t + 1]),
                                              dvec3(corners[3 * t + 2]));
            if (th >= 0.0) hits.push_back(th);
        }
        for (uint32_t n = 0; n < nodes.size(); ++n) {
            float te, tx;
            if (!nb_intersect_aabb_interval(org, nb_safe_inv_dir(dir), nodes[n].bounds.lo, nodes[n].bounds.hi, 0.0f,
                                            NB_INF, te, tx))
                continue;
            ++segments;
            const bool occupied = occupancy_segment_occupied(&w[n * NB_OCC_WORDS], org, dir, nodes[n].bounds, te, tx);
            culled += !occupied;
            const bool hit = std::any_of(hits.begin(), hits.end(), [&](double t) { return t >= te && t <= tx; });
            if (hit && !occupied && violations++ == 0) first = "ray " + std::to_string(r) + " node " + std::to_string(n);
        }
    }
    std::printf("[ conservativeness ] %d node segments, %d culled, %d violations\n", segments, culled, violations);
    EXPECT_EQ(violations, 0) << first;
    EXPECT_GT(culled, segments / 20);
    EXPECT_LT(culled, segments);
}

// A ray skimming the face x = lo.x of a box 100 away from the origin, one float step (7.6e-6) inside it
// and drifting out at 4e-6 per unit: its true path stays inside the box for y in [0, 0.907] (cells
// y 0..7), where it hits a triangle poking through the face at y = 0.55. Its start rounds onto the face
// (p.x = 0 in float) with exact true (rounding bound 1e-3 cell). A walk that ends when a step leaves the
// grid (x -> -1) visits only cell (0, 0, 3): the pair is culled and the hit lost, which no marking
// margin covers. The walk must keep the boundary cell on that axis and go on along the others.
TEST(Occupancy, GrazingSegmentWhoseStartRoundsOntoTheFace) {
    const vec3 lo(100.0f, 0.0f, 0.0f), hi(101.0f, 1.0f, 1.0f);
    const vec3 org(std::nextafter(100.0f, 200.0f), -1.0f, 0.45f), dir(-4.0e-6f, 1.0f, 0.0f);
    const std::vector<vec3> tri{{99.9f, 0.55f, 0.4f}, {100.1f, 0.55f, 0.4f}, {100.0f, 0.55f, 0.7f}};
    const std::vector<uint32_t> w = build_occupancy(std::vector<NbvhNode>{make_node(lo, hi, NBVH_NO_CHILD, 0)}, make_mesh(tri), 1);
    const double th = moller_trumbore(dvec3(org), dvec3(dir), dvec3(tri[0]), dvec3(tri[1]), dvec3(tri[2]));
    ASSERT_GT(th, 1.5); // a true hit at x = 100 + 1.4e-6, inside the box
    float te, tx;
    ASSERT_TRUE(nb_neural_leaf_interval(org, nb_safe_inv_dir(dir), lo, hi, te, tx)); // as the GPU traversal does
    ASSERT_TRUE(th >= te && th <= tx) << te << ".." << tx;
    EXPECT_TRUE(occupancy_segment_occupied(w.data(), org, dir, Aabb{lo, hi}, te, tx))
        << "segment " << te << ".." << tx << " culled; walk visits " << walk_cells(org, dir, lo, hi, te, tx).size()
        << " cell(s)";
    WalkStats st;
    EXPECT_EQ(check_walk(org, dir, lo, hi, te, tx, st), "");
}

TEST(Occupancy, Fraction) {
    const std::vector<NbvhNode> nodes = two_leaves(1);
    const NbvhTree tree = NbvhTree::from_nodes(nodes, 3);
    const std::vector<uint32_t> ones(nodes.size() * NB_OCC_WORDS, ~0u);
    for (uint32_t lod = 0; lod < 3; ++lod) EXPECT_DOUBLE_EQ(occupancy_fraction(tree, ones, lod), 1.0);
    const std::vector<uint32_t> w = build_occupancy(nodes, one_triangle(), 0);
    const double f0 = occupancy_fraction(tree, w, 0), f1 = occupancy_fraction(tree, w, 1);
    EXPECT_GT(f0, 0.0);
    EXPECT_LT(f0, 0.1);
    EXPECT_DOUBLE_EQ(f0, 1.0 / 1024.0); // one cell of two leaves
    EXPECT_DOUBLE_EQ(f1, 1.0 / 512.0);  // one cell of the root
}

} // namespace
} // namespace nbvh
