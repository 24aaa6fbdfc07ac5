// Hard cases of the shared ray/box and ray/triangle math (shaders/shared/intersect.h).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "shaders/shared/intersect.h"

namespace {

const float INF = std::numeric_limits<float>::infinity();

bool box(vec3 o, vec3 d, vec3 lo, vec3 hi, float tmin, float tmax, float& tn, float& tf, bool safe_inv) {
    vec3 inv = safe_inv ? nb_safe_inv_dir(d) : vec3(1.0f) / d; // 1/0 = +-inf on the CPU
    bool h = nb_intersect_aabb_interval(o, inv, lo, hi, tmin, tmax, tn, tf);
    EXPECT_FALSE(std::isnan(tn) || std::isnan(tf));
    float tn2;
    EXPECT_EQ(h, nb_intersect_aabb(o, inv, lo, hi, tmin, tmax, tn2));
    if (h) {
        EXPECT_EQ(tn, tn2);
    }
    return h;
}

// Exact reference in double: the set {t in [tmin, tmax] : o + t d in [lo, hi]} is non-empty.
bool box_reference(vec3 o, vec3 d, vec3 lo, vec3 hi, double tmin, double tmax) {
    for (int a = 0; a < 3; ++a) {
        if (lo[a] > hi[a]) return false;
        if (d[a] == 0.0f) {
            if (o[a] < lo[a] || o[a] > hi[a]) return false;
            continue;
        }
        double t0 = (double(lo[a]) - o[a]) / d[a], t1 = (double(hi[a]) - o[a]) / d[a];
        tmin = std::max(tmin, std::min(t0, t1));
        tmax = std::min(tmax, std::max(t0, t1));
    }
    return tmin <= tmax;
}

TEST(Intersect, AxisParallelRayInPlaneOfFlatBox) {
    float tn, tf;
    for (bool safe : {false, true}) {
        // Box flat in y (extent 0); ray along +x inside its plane.
        EXPECT_TRUE(box(vec3(-1.0f, 0.0f, 0.5f), vec3(1.0f, 0.0f, 0.0f), vec3(0.0f), vec3(1.0f, 0.0f, 1.0f), 0.0f, NB_INF, tn, tf, safe));
        EXPECT_NEAR(tn, 1.0f, 2e-5f); // widened by NB_SLAB_SLACK
        EXPECT_NEAR(tf, 2.0f, 1e-5f);
        // Same with a -0 direction component.
        EXPECT_TRUE(box(vec3(-1.0f, 0.0f, 0.5f), vec3(1.0f, -0.0f, -0.0f), vec3(0.0f), vec3(1.0f, 0.0f, 1.0f), 0.0f, NB_INF, tn, tf, safe));
        // Slightly off the plane: miss.
        EXPECT_FALSE(box(vec3(-1.0f, 1e-7f, 0.5f), vec3(1.0f, 0.0f, 0.0f), vec3(0.0f), vec3(1.0f, 0.0f, 1.0f), 0.0f, NB_INF, tn, tf, safe));
        // Perpendicular through the flat box: entry == exit.
        EXPECT_TRUE(box(vec3(0.5f, -1.0f, 0.5f), vec3(0.0f, 1.0f, 0.0f), vec3(0.0f), vec3(1.0f, 0.0f, 1.0f), 0.0f, NB_INF, tn, tf, safe));
        EXPECT_NEAR(tn, 1.0f, 2e-5f); // widened by NB_SLAB_SLACK
        EXPECT_NEAR(tf, 1.0f, 1e-5f);
        // A box that is a single point, ray through it along an axis.
        EXPECT_TRUE(box(vec3(2.0f, 3.0f, -5.0f), vec3(0.0f, 0.0f, 2.0f), vec3(2.0f, 3.0f, 4.0f), vec3(2.0f, 3.0f, 4.0f), 0.0f, NB_INF, tn, tf, safe));
        EXPECT_NEAR(tn, 4.5f, 2e-5f); // widened by NB_SLAB_SLACK
    }
}

TEST(Intersect, OriginOnFaceCountsAsInside) {
    float tn, tf;
    for (bool safe : {false, true}) {
        // Leaving through the face the origin lies on: touches at t = 0.
        EXPECT_TRUE(box(vec3(0.0f, 0.5f, 0.5f), vec3(-1.0f, 0.0f, 0.0f), vec3(0.0f), vec3(1.0f), 0.0f, NB_INF, tn, tf, safe));
        EXPECT_EQ(tn, 0.0f);
        // Entering from the face.
        EXPECT_TRUE(box(vec3(0.0f, 0.5f, 0.5f), vec3(1.0f, 0.0f, 0.0f), vec3(0.0f), vec3(1.0f), 0.0f, NB_INF, tn, tf, safe));
        EXPECT_EQ(tn, 0.0f);
        EXPECT_NEAR(tf, 1.0f, 1e-5f);
        // On a face, moving along it (parallel axis exactly on the slab boundary).
        EXPECT_TRUE(box(vec3(0.0f, 0.5f, 0.5f), vec3(0.0f, 1.0f, 0.0f), vec3(0.0f), vec3(1.0f), 0.0f, NB_INF, tn, tf, safe));
        // On an edge moving along the edge.
        EXPECT_TRUE(box(vec3(0.0f, 0.0f, -3.0f), vec3(0.0f, 0.0f, 1.0f), vec3(0.0f), vec3(1.0f), 0.0f, NB_INF, tn, tf, safe));
        EXPECT_NEAR(tn, 3.0f, 2e-5f); // widened by NB_SLAB_SLACK
        // Neural-query clipping: tmin = -inf from inside gives a negative entry.
        EXPECT_TRUE(box(vec3(0.25f, 0.5f, 0.5f), vec3(1.0f, 0.0f, 0.0f), vec3(0.0f), vec3(1.0f), -NB_INF, NB_INF, tn, tf, safe));
        EXPECT_NEAR(tn, -0.25f, 2e-5f); // widened by NB_SLAB_SLACK
        EXPECT_NEAR(tf, 0.75f, 1e-5f);
    }
}

TEST(Intersect, EmptyBoxesAndRangeNeverHit) {
    float tn, tf;
    EXPECT_FALSE(box(vec3(0.0f), vec3(1.0f, 0.0f, 0.0f), vec3(NB_INF), vec3(-NB_INF), -NB_INF, NB_INF, tn, tf, true));
    EXPECT_FALSE(box(vec3(0.0f), vec3(1.0f, 0.0f, 0.0f), vec3(NB_INF), vec3(-NB_INF), -NB_INF, NB_INF, tn, tf, false));
    EXPECT_FALSE(box(vec3(0.0f), vec3(1.0f, 1.0f, 1.0f), vec3(-1.0f), vec3(1.0f), 2.0f, 1.0f, tn, tf, true));
    EXPECT_FALSE(box(vec3(-5.0f, 0.0f, 0.0f), vec3(1.0f, 0.0f, 0.0f), vec3(-1.0f), vec3(1.0f), 0.0f, 3.9f, tn, tf, true));
    // A NaN ray reports no hit.
    float nan = std::nanf("");
    float tn2;
    EXPECT_FALSE(nb_intersect_aabb(vec3(nan), vec3(1.0f), vec3(-1.0f), vec3(1.0f), 0.0f, NB_INF, tn2));
}

// Exhaustive small integer cases (exact in float): matches the exact reference, never NaN.
TEST(Intersect, BoxMatchesExactReferenceOnIntegerGrid) {
    const float vals[] = {-1.0f, -0.0f, 0.0f, 1.0f, 2.0f};
    const float coords[] = {-1.0f, 0.0f, 1.0f, 2.0f};
    std::mt19937 rng(7);
    int hits = 0, count = 0;
    for (int trial = 0; trial < 40000; ++trial) {
        auto pick = [&](const float* a, int n) { return a[rng() % n]; };
        vec3 o(pick(coords, 4), pick(coords, 4), pick(coords, 4));
        vec3 d(pick(vals, 5), pick(vals, 5), pick(vals, 5));
        vec3 lo(pick(coords, 4), pick(coords, 4), pick(coords, 4));
        vec3 hi = lo + vec3(float(rng() % 2), float(rng() % 2), float(rng() % 3));
        if (d == vec3(0.0f)) continue;
        for (bool safe : {false, true}) {
            float tn, tf;
            bool h = box(o, d, lo, hi, 0.0f, NB_INF, tn, tf, safe);
            ASSERT_EQ(h, box_reference(o, d, lo, hi, 0.0, NB_INF))
                << "o=" << o.x << "," << o.y << "," << o.z << " d=" << d.x << "," << d.y << "," << d.z << " lo=" << lo.x
                << "," << lo.y << "," << lo.z << " hi=" << hi.x << "," << hi.y << "," << hi.z;
            hits += h;
            ++count;
        }
    }
    EXPECT_GT(hits, count / 20); // the cases are not all trivial misses
}

bool tri(vec3 o, vec3 d, vec3 a, vec3 b, vec3 c, float& t, float& u, float& v, float tmax = NB_INF) {
    t = u = v = -7.0f;
    bool h = nb_intersect_triangle(o, d, a, b, c, 0.0f, tmax, t, u, v);
    if (h) {
        EXPECT_TRUE(std::isfinite(t) && std::isfinite(u) && std::isfinite(v));
        EXPECT_GE(u, 0.0f);
        EXPECT_GE(v, 0.0f);
        EXPECT_LE(u + v, 1.0f + 1e-6f);
    } else {
        EXPECT_EQ(t, -7.0f); // outputs untouched on a miss
    }
    return h;
}

TEST(Intersect, TriangleBasicsAndBarycentrics) {
    float t, u, v;
    vec3 a(0.0f), b(1.0f, 0.0f, 0.0f), c(0.0f, 1.0f, 0.0f);
    ASSERT_TRUE(tri(vec3(0.25f, 0.5f, 2.0f), vec3(0.0f, 0.0f, -1.0f), a, b, c, t, u, v));
    EXPECT_FLOAT_EQ(t, 2.0f);
    EXPECT_FLOAT_EQ(u, 0.25f);
    EXPECT_FLOAT_EQ(v, 0.5f);
    // Both facings hit; unnormalised direction scales t.
    ASSERT_TRUE(tri(vec3(0.25f, 0.25f, -2.0f), vec3(0.0f, 0.0f, 4.0f), a, b, c, t, u, v));
    EXPECT_FLOAT_EQ(t, 0.5f);
    // Behind the origin / beyond tmax: miss.
    EXPECT_FALSE(tri(vec3(0.25f, 0.25f, -2.0f), vec3(0.0f, 0.0f, -1.0f), a, b, c, t, u, v));
    EXPECT_FALSE(tri(vec3(0.25f, 0.25f, -2.0f), vec3(0.0f, 0.0f, 1.0f), a, b, c, t, u, v, 1.5f));
    // Outside.
    EXPECT_FALSE(tri(vec3(0.75f, 0.75f, 1.0f), vec3(0.0f, 0.0f, -1.0f), a, b, c, t, u, v));
    // Zero direction.
    EXPECT_FALSE(tri(vec3(0.25f, 0.25f, 0.0f), vec3(0.0f), a, b, c, t, u, v));
}

TEST(Intersect, DegenerateTrianglesNeverHit) {
    float t, u, v;
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> r(-1.0f, 1.0f);
    for (int i = 0; i < 2000; ++i) {
        // Dyadic coordinates so that the midpoint below is exactly collinear.
        auto dy = [&] { return float(int(rng() % 33) - 16) / 8.0f; };
        vec3 p(dy(), dy(), dy()), q(dy(), dy(), dy());
        vec3 o(r(rng) * 3.0f, r(rng) * 3.0f, r(rng) * 3.0f);
        // Aim at a point of the degenerate triangle.
        vec3 d = p - o;
        EXPECT_FALSE(tri(o, d, p, p, p, t, u, v));                           // a point
        EXPECT_FALSE(tri(o, d, p, q, p, t, u, v));                           // repeated vertex
        EXPECT_FALSE(tri(o, 0.5f * (p + q) - o, p, q, 0.5f * (p + q), t, u, v)); // collinear (midpoint exact-ish)
    }
}

TEST(Intersect, GrazingRaysInTrianglePlane) {
    float t, u, v;
    vec3 a(0.0f), b(1.0f, 0.0f, 0.0f), c(0.0f, 1.0f, 0.0f);
    // In the plane, through the interior: det == 0, no hit, no NaN.
    EXPECT_FALSE(tri(vec3(-1.0f, 0.2f, 0.0f), vec3(1.0f, 0.0f, 0.0f), a, b, c, t, u, v));
    EXPECT_FALSE(tri(vec3(-1.0f, -1.0f, 0.0f), vec3(1.0f, 1.0f, 0.0f), a, b, c, t, u, v));
    // Nearly in the plane: whatever the result, it is finite and consistent (checked in tri()).
    for (float eps : {1e-3f, 1e-6f, 1e-12f, 1e-30f}) {
        tri(vec3(-1.0f, 0.2f, eps), vec3(1.0f, 0.0f, -eps), a, b, c, t, u, v);
    }
}

// Rays through a shared edge or vertex hit at least one of the triangles (no leaks).
TEST(Intersect, WatertightOnSharedEdgesAndVertices) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> r(-1.0f, 1.0f), s(0.0f, 1.0f);
    // A fan of 6 triangles around a centre vertex, not axis-aligned.
    vec3 centre(0.3f, -0.2f, 0.1f);
    vec3 ring[6];
    for (int k = 0; k < 6; ++k) {
        float ang = float(k) * 1.0471976f;
        ring[k] = centre + vec3(std::cos(ang), 0.37f * std::sin(ang), std::sin(ang));
    }
    int misses = 0;
    for (int i = 0; i < 20000; ++i) {
        vec3 o(r(rng) * 4.0f, 3.0f + r(rng), r(rng) * 4.0f);
        int k = int(rng() % 6);
        // Target: the centre vertex, or a point on spoke k.
        vec3 target = (i % 4 == 0) ? centre : centre + s(rng) * (ring[k] - centre);
        vec3 d = target - o;
        bool any = false;
        for (int j = 0; j < 6; ++j) {
            float t, u, v;
            any |= nb_intersect_triangle(o, d, centre, ring[j], ring[(j + 1) % 6], 0.0f, NB_INF, t, u, v);
        }
        misses += !any;
    }
    EXPECT_EQ(misses, 0);
}

// Möller-Trumbore in double (the float inputs are exact in double): t, u, v of the infinite plane hit.
bool reference_triangle(vec3 o, vec3 d, vec3 a, vec3 b, vec3 c, double& t, double& u, double& v) {
    glm::dvec3 O(o), D(d), A(a), B(b), C(c);
    glm::dvec3 e1 = B - A, e2 = C - A, pv = glm::cross(D, e2);
    double det = glm::dot(e1, pv);
    if (det == 0.0) return false;
    glm::dvec3 tv = O - A, qv = glm::cross(tv, e1);
    u = glm::dot(tv, pv) / det;
    v = glm::dot(D, qv) / det;
    t = glm::dot(e2, qv) / det;
    return true;
}

// Triangles at 1e-3 and 1e5 scale, and far from the origin: hits are found with small relative
// error in t and misses just outside stay misses.
TEST(Intersect, TrianglesAtExtremeScalesAndOffsets) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> r(-1.0f, 1.0f), s(0.05f, 0.9f);
    for (float scale : {1e-3f, 1.0f, 1e5f}) {
        for (float offset : {0.0f, 1e5f}) {
            if (scale < 1.0f && offset > 0.0f) continue; // 1e-3 triangles at 1e5: below float resolution
            int hits = 0;
            for (int i = 0; i < 500; ++i) {
                vec3 off(offset, -offset, offset * 0.5f);
                vec3 a = off + scale * vec3(r(rng), r(rng), r(rng));
                vec3 b = off + scale * vec3(r(rng), r(rng), r(rng));
                vec3 c = off + scale * vec3(r(rng), r(rng), r(rng));
                vec3 n = cross(b - a, c - a);
                if (length(n) < 0.05f * scale * scale) continue; // skip near-degenerate ones
                n = normalize(n);
                float bu = s(rng) * 0.5f, bv = s(rng) * 0.5f;
                vec3 p = a + bu * (b - a) + bv * (c - a);
                vec3 o = p + 3.0f * scale * normalize(n + 0.3f * vec3(r(rng), r(rng), r(rng)));
                float t, u, v;
                vec3 d = p - o;
                bool h = tri(o, d, a, b, c, t, u, v);
                hits += h;
                double rt, ru, rv;
                ASSERT_TRUE(reference_triangle(o, d, a, b, c, rt, ru, rv));
                if (h) {
                    EXPECT_NEAR(t, rt, 1e-4);
                    EXPECT_NEAR(u, ru, 1e-4);
                    EXPECT_NEAR(v, rv, 1e-4);
                } else {
                    // Only a hit on the boundary within rounding may be missed.
                    EXPECT_TRUE(ru < 1e-4 || rv < 1e-4 || ru + rv > 1.0 - 1e-4) << ru << " " << rv;
                }
                // Beyond an edge (outside the triangle by 10% of its size): miss.
                vec3 q = a - 0.1f * ((b - a) + (c - a));
                EXPECT_FALSE(tri(o, q - o, a, b, c, t, u, v));
            }
            EXPECT_GT(hits, 100) << "scale " << scale << " offset " << offset;
        }
    }
}

TEST(Intersect, SafeInverseDirection) {
    vec3 inv = nb_safe_inv_dir(vec3(0.0f, -0.0f, 2.0f));
    EXPECT_EQ(inv.x, NB_INF);
    EXPECT_EQ(std::abs(inv.y), NB_INF);
    EXPECT_EQ(inv.z, 0.5f);
    inv = nb_safe_inv_dir(vec3(-1e-35f, 1e-20f, -4.0f));
    EXPECT_EQ(inv.x, -NB_INF);
    EXPECT_FLOAT_EQ(inv.y, 1e20f);
    EXPECT_TRUE(std::isfinite(inv.x));
    (void)INF;
}

// The branch-free slab (selects only, both distances computed on a parallel axis too): a parallel axis
// with the origin on the slab's face, inside, outside, or NaN; with the safe inverse (+-NB_INF, finite)
// and IEEE infinities (where (lo - o) * inf is NaN for an origin on the face and must be discarded).
TEST(Intersect, ParallelAxisSelectsNeverLeakNaN) {
    const float nan = std::nanf("");
    for (bool safe : {true, false}) {
        float tn, tf;
        // On the face x = lo, parallel to x: inside the closed slab.
        EXPECT_TRUE(box(vec3(-1.0f, 0.0f, -5.0f), vec3(0.0f, 0.0f, 1.0f), vec3(-1.0f), vec3(1.0f), 0.0f, NB_INF, tn, tf, safe));
        EXPECT_LE(tn, 4.0f); // widened by NB_SLAB_SLACK
        EXPECT_GT(tn, 3.9999f);
        // On the far face x = hi, and outside by one ulp.
        EXPECT_TRUE(box(vec3(1.0f, 0.0f, -5.0f), vec3(0.0f, 0.0f, 1.0f), vec3(-1.0f), vec3(1.0f), 0.0f, NB_INF, tn, tf, safe));
        EXPECT_FALSE(box(vec3(std::nextafter(1.0f, 2.0f), 0.0f, -5.0f), vec3(0.0f, 0.0f, 1.0f), vec3(-1.0f), vec3(1.0f),
                         0.0f, NB_INF, tn, tf, safe));
        // Parallel to two axes, in a flat box's plane.
        EXPECT_TRUE(box(vec3(0.0f, 2.0f, -5.0f), vec3(0.0f, 0.0f, 1.0f), vec3(-1.0f, 2.0f, -1.0f), vec3(1.0f, 2.0f, 1.0f),
                        0.0f, NB_INF, tn, tf, safe));
    }
    // A NaN origin component on a parallel axis: no hit (no NaN read as "inside").
    float tn;
    EXPECT_FALSE(nb_intersect_aabb(vec3(nan, 0.0f, -5.0f), nb_safe_inv_dir(vec3(0.0f, 0.0f, 1.0f)), vec3(-1.0f), vec3(1.0f),
                                   0.0f, NB_INF, tn));
}

// Traversal computes the ray's shear once (nb_ray_shear) and tests triangles with
// nb_intersect_triangle_sheared: bit-identical to nb_intersect_triangle, for every dominant axis and
// sign, axis-parallel and grazing directions, far-from-origin rays; zero and NaN directions have no shear.
TEST(Intersect, ShearedTriangleTestMatchesPerCallTest) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> U(-1.0f, 1.0f);
    const vec3 axes[] = {vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 1, 0), vec3(0, -1, 0), vec3(0, 0, 1), vec3(0, 0, -1)};
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
        const float scale = (i % 3 == 0) ? 1.0e4f : 1.0f;
        const vec3 off = (i % 5 == 0) ? vec3(3.0e6f, -2.0e6f, 1.0e6f) : vec3(0.0f);
        vec3 v0 = off + scale * vec3(U(rng), U(rng), U(rng)), v1 = off + scale * vec3(U(rng), U(rng), U(rng)),
             v2 = off + scale * vec3(U(rng), U(rng), U(rng));
        vec3 o = off + scale * 3.0f * vec3(U(rng), U(rng), U(rng));
        vec3 target = (v0 + v1 + v2) / 3.0f + 0.3f * scale * vec3(U(rng), U(rng), U(rng));
        vec3 d = (i % 7 == 0) ? axes[i % 6] : target - o;
        if (i % 11 == 0) d.y = 0.0f; // parallel to an axis
        float t0 = -1, u0 = -1, w0 = -1, t1 = -2, u1 = -2, w1 = -2;
        NbRayShear sh;
        const bool valid = nb_ray_shear(d, sh);
        const bool h0 = nb_intersect_triangle(o, d, v0, v1, v2, 0.0f, NB_INF, t0, u0, w0);
        const bool h1 = valid && nb_intersect_triangle_sheared(o, sh, v0, v1, v2, 0.0f, NB_INF, t1, u1, w1);
        ASSERT_EQ(h0, h1) << i;
        if (h0) {
            ++hits;
            EXPECT_EQ(t0, t1);
            EXPECT_EQ(u0, u1);
            EXPECT_EQ(w0, w1);
        }
    }
    EXPECT_GT(hits, 2000);
    NbRayShear sh;
    EXPECT_FALSE(nb_ray_shear(vec3(0.0f), sh));
    float t, u, v;
    EXPECT_FALSE(nb_intersect_triangle(vec3(0, 0, -1), vec3(std::nanf("")), vec3(-1, -1, 0), vec3(1, -1, 0),
                                       vec3(0, 1, 0), 0.0f, NB_INF, t, u, v));
}

} // namespace
