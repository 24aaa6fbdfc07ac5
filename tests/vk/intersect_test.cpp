// Ray-box and ray-triangle kernels (shaders/shared/intersect.h) on lavapipe against the C++ build of
// the same header, on random rays and on the hard cases of a slab/watertight test: axis-parallel
// rays against flat boxes, origins on faces, edges and corners, rays through vertices and shared
// edges, rays in a triangle's plane, triangles at 1e-3 and 1e5 scale and far from the origin.
//
// Hit flags must match exactly. Distances are compared within a relative bound (below): Vulkan only
// guarantees 2.5 ulp for division and lets the driver fuse a*b+c, so bit equality is not promised.
#include "engine/core/log.h"
#include "engine/vk/kernel_runner.h"
#include "shaders/shared/intersect.h"
#include "shaders/tests/intersect_case.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

using namespace nbvh::vk;

namespace {

// |gpu - cpu| <= REL_T * max(|cpu|, |gpu|, scale) for t (scale: the case's coordinate magnitude
// divided by |dir|, so t near 0 is compared against the size of the scene, not against 0).
constexpr float REL_T = 1e-5f;
constexpr float ABS_UV = 1e-4f; // barycentrics are in [0, 1]

struct Case {
    vec3 org, dir;
    float tmin = 0.0f, tmax = NB_INF;
    vec3 lo, hi, v0, v1, v2;
    bool tight_box = false; // box == triangle bounds: a triangle hit implies a box hit
    std::string kind;
};

struct Result {
    bool box = false, tri = false;
    float t_near = 0, t_far = 0, t = 0, u = 0, v = 0;
};

Result run_cpu(const Case& c) {
    Result r;
    r.box = nb_intersect_aabb_interval(c.org, nb_safe_inv_dir(c.dir), c.lo, c.hi, c.tmin, c.tmax, r.t_near, r.t_far);
    r.tri = nb_intersect_triangle(c.org, c.dir, c.v0, c.v1, c.v2, c.tmin, c.tmax, r.t, r.u, r.v);
    return r;
}

void tri_bounds(Case& c) {
    c.lo = min(c.v0, min(c.v1, c.v2));
    c.hi = max(c.v0, max(c.v1, c.v2));
    c.tight_box = true;
}

class Cases {
public:
    std::vector<Case> all;
    std::mt19937 rng{12345u};
    float uni(float a, float b) { return std::uniform_real_distribution<float>(a, b)(rng); }
    vec3 uni3(float a, float b) { return vec3(uni(a, b), uni(a, b), uni(a, b)); }
    vec3 unit() {
        for (;;) {
            vec3 d = uni3(-1, 1);
            float l = length(d);
            if (l > 0.1f && l <= 1.0f) return d / l;
        }
    }
    void add(Case c, const char* kind) {
        c.kind = kind;
        all.push_back(c);
    }

    void random(int n) {
        for (int i = 0; i < n; ++i) {
            Case c;
            vec3 target = uni3(-2, 2);
            c.org = uni3(-10, 10);
            c.dir = (target - c.org) * uni(0.05f, 2.0f); // not normalised
            vec3 centre = uni3(-3, 3), half = uni3(0.01f, 3.0f);
            c.lo = centre - half;
            c.hi = centre + half;
            c.v0 = target + uni3(-1.5f, 1.5f);
            c.v1 = target + uni3(-1.5f, 1.5f);
            c.v2 = target + uni3(-1.5f, 1.5f);
            int range = i % 4;
            c.tmin = range == 3 ? -NB_INF : 0.0f;
            c.tmax = range == 1 ? uni(0.1f, 3.0f) : NB_INF;
            if (i % 2) tri_bounds(c);
            add(c, "random");
        }
    }

    // Axis-parallel rays (other direction components exactly 0) against flat and regular boxes.
    void axis_parallel_flat_boxes() {
        for (int axis = 0; axis < 3; ++axis)
            for (int sign = -1; sign <= 1; sign += 2)
                for (int flat = 0; flat < 3; ++flat)
                    for (int where = 0; where < 5; ++where) {
                        Case c;
                        c.dir = vec3(0.0f);
                        c.dir[axis] = float(sign) * (where % 2 ? 0.5f : 1.0f);
                        c.lo = vec3(-1.0f, -2.0f, 0.5f);
                        c.hi = vec3(1.0f, 2.0f, 3.0f);
                        c.hi[flat] = c.lo[flat]; // a flat box (e.g. a BVH node of a planar mesh)
                        vec3 centre = 0.5f * (c.lo + c.hi);
                        c.org = centre;
                        c.org[axis] -= float(sign) * 10.0f; // in front, looking at the box
                        int side = (axis + 1) % 3;
                        if (where == 1) c.org[side] = c.lo[side];          // on the slab boundary
                        if (where == 2) c.org[side] = c.hi[side];
                        if (where == 3) c.org[side] = std::nextafter(c.hi[side], 1e30f); // just outside
                        if (where == 4) c.org[axis] = centre[axis];                    // inside
                        c.tmin = where == 4 ? -NB_INF : 0.0f;
                        // A triangle in the flat box's plane (the ray crosses or lies in it).
                        c.v0 = c.lo;
                        c.v1 = c.lo;
                        c.v1[(flat + 1) % 3] = c.hi[(flat + 1) % 3];
                        c.v2 = c.lo;
                        c.v2[(flat + 2) % 3] = c.hi[(flat + 2) % 3];
                        add(c, "axis-parallel vs flat box");
                    }
    }

    // Origins exactly on faces, edges and corners of a box, rays in every direction class.
    void origins_on_box() {
        const vec3 lo(-1.0f, 0.25f, 2.0f), hi(3.0f, 1.5f, 2.125f);
        for (int i = 0; i < 400; ++i) {
            Case c;
            c.lo = lo;
            c.hi = hi;
            c.org = uni3(0, 1) * (hi - lo) + lo;
            int snap = i % 7; // 1-3 faces, 4-5 edges, 6 a corner
            for (int a = 0; a < 3; ++a)
                if ((snap == 1 + a) || (snap == 4 && a != 2) || (snap == 5 && a != 0) || snap == 6)
                    c.org[a] = (i / 7) % 2 ? hi[a] : lo[a];
            c.dir = unit();
            if (i % 3 == 0) { // axis-parallel: along or across the face
                c.dir = vec3(0.0f);
                c.dir[i % 5 % 3] = (i % 2) ? 1.0f : -1.0f;
            }
            c.v0 = lo;
            c.v1 = vec3(hi.x, lo.y, lo.z);
            c.v2 = vec3(lo.x, hi.y, hi.z);
            c.tmin = (i % 4 == 0) ? -NB_INF : 0.0f;
            add(c, "origin on box face/edge/corner");
        }
    }

    // Rays through a vertex, through a shared edge (two triangles: watertightness), and rays lying
    // in the triangle's plane; the box is the triangle's bounds.
    void grazing(float scale, vec3 offset, int n, const char* kind) {
        for (int i = 0; i < n; ++i) {
            vec3 a = offset + scale * uni3(-1, 1), b = offset + scale * uni3(-1, 1), d = offset + scale * uni3(-1, 1);
            // Fourth vertex: the parallelogram completion, so the two triangles lie on opposite sides
            // of the shared edge (b, d) for every ray that crosses their plane.
            vec3 e = b + d - a;
            vec3 org = offset + scale * 4.0f * unit();
            int mode = i % 4;
            vec3 target = mode == 0 ? a : (mode == 1 ? b + uni(0, 1) * (d - b) : (a + b + d) / 3.0f);
            Case c;
            c.org = org;
            c.dir = target - org;
            if (mode == 3) { // in the plane of (a, b, d): origin on the plane, direction along an edge
                c.org = a + 2.0f * (a - b);
                c.dir = b - a;
            }
            c.v0 = a;
            c.v1 = b;
            c.v2 = d;
            tri_bounds(c);
            add(c, kind);
            // Second triangle sharing edge (b, d) with the first, on the other side (same ray).
            c.v0 = d;
            c.v1 = b;
            c.v2 = e;
            tri_bounds(c);
            add(c, kind);
        }
    }

    void degenerate() {
        Case c;
        c.org = vec3(0.0f, 0.0f, -5.0f);
        c.dir = vec3(0.0f, 0.0f, 1.0f);
        c.v0 = c.v1 = c.v2 = vec3(0.0f); // zero-area point triangle
        tri_bounds(c);
        add(c, "degenerate");
        c.v1 = vec3(1.0f, 1.0f, 0.0f);
        c.v2 = vec3(2.0f, 2.0f, 0.0f); // collinear
        tri_bounds(c);
        add(c, "degenerate");
        c.dir = vec3(0.0f); // zero direction
        add(c, "degenerate");
        c.lo = vec3(1.0f);
        c.hi = vec3(-1.0f); // empty box
        c.dir = vec3(0.0f, 0.0f, 1.0f);
        c.tight_box = false;
        add(c, "degenerate");
    }
};

std::vector<float> pack(const std::vector<Case>& cases) {
    std::vector<float> f(cases.size() * NB_IC_IN, 0.0f);
    auto put = [&](size_t base, uint32_t field, vec3 v) {
        f[base + field] = v.x;
        f[base + field + 1] = v.y;
        f[base + field + 2] = v.z;
    };
    for (size_t i = 0; i < cases.size(); ++i) {
        const Case& c = cases[i];
        size_t b = i * NB_IC_IN;
        put(b, NB_IC_ORG, c.org);
        put(b, NB_IC_DIR, c.dir);
        f[b + NB_IC_TMIN] = c.tmin;
        f[b + NB_IC_TMAX] = c.tmax;
        put(b, NB_IC_LO, c.lo);
        put(b, NB_IC_HI, c.hi);
        put(b, NB_IC_V0, c.v0);
        put(b, NB_IC_V1, c.v1);
        put(b, NB_IC_V2, c.v2);
    }
    return f;
}

float as_float(uint32_t bits) {
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
}

bool t_close(float gpu, float cpu, float scale) {
    if (gpu == cpu) return true; // also equal sentinels
    float bound = REL_T * std::max({std::fabs(cpu), std::fabs(gpu), scale});
    return std::fabs(gpu - cpu) <= bound;
}

std::string describe(const Case& c) {
    auto v = [](vec3 p) { return nbvh::strfmt("(%.9g, %.9g, %.9g)", p.x, p.y, p.z); };
    return c.kind + ": org " + v(c.org) + " dir " + v(c.dir) + nbvh::strfmt(" t [%g, %g]", c.tmin, c.tmax) +
           " box " + v(c.lo) + "-" + v(c.hi) + " tri " + v(c.v0) + v(c.v1) + v(c.v2);
}

} // namespace

TEST(VkIntersect, MatchesCppBuildOfSharedHeader) {
    Cases gen;
    gen.random(4000);
    gen.axis_parallel_flat_boxes();
    gen.origins_on_box();
    gen.grazing(1.0f, vec3(0.0f), 400, "grazing, unit scale");
    gen.grazing(1e-3f, vec3(0.0f), 300, "grazing, 1e-3 scale");
    gen.grazing(1e5f, vec3(0.0f), 300, "grazing, 1e5 scale");
    gen.grazing(1.0f, vec3(1e4f, -2e4f, 3e4f), 300, "grazing, unit scale far from origin");
    gen.grazing(1e-3f, vec3(-1e3f, 5e2f, 1e3f), 300, "grazing, 1e-3 scale far from origin");
    gen.degenerate();
    const std::vector<Case>& cases = gen.all;

    KernelRunner run;
    Buffer in = run.input(pack(cases), "cases");
    Buffer out = run.output<uint32_t>(cases.size() * NB_IC_OUT, "results");
    struct {
        uint32_t count;
    } push{uint32_t(cases.size())};
    run.dispatch({.shader = "tests/intersect.comp", .bindings = {&in, &out}, .items = cases.size(),
                  .group_size = 64, .push = push_bytes(push)});
    std::vector<uint32_t> words = run.read<uint32_t>(out, cases.size() * NB_IC_OUT);
    EXPECT_EQ(run.validation_messages(), 0);

    int box_hits = 0, tri_hits = 0, failures = 0;
    float worst_t = 0.0f;
    for (size_t i = 0; i < cases.size() && failures < 20; ++i) {
        const Case& c = cases[i];
        const Result cpu = run_cpu(c);
        const uint32_t* w = &words[i * NB_IC_OUT];
        Result gpu;
        gpu.box = w[NB_IC_BOX_HIT] != 0u;
        gpu.t_near = as_float(w[NB_IC_BOX_NEAR]);
        gpu.t_far = as_float(w[NB_IC_BOX_FAR]);
        gpu.tri = w[NB_IC_TRI_HIT] != 0u;
        gpu.t = as_float(w[NB_IC_TRI_T]);
        gpu.u = as_float(w[NB_IC_TRI_U]);
        gpu.v = as_float(w[NB_IC_TRI_V]);
        // t of a point at the case's coordinate magnitude: the scale t errors are relative to.
        float coord = std::max({length(c.org), length(c.v0), length(c.lo), length(c.hi)});
        float scale = coord / std::max(length(c.dir), 1e-30f);
        bool ok = true;
        auto fail = [&](const std::string& what) {
            ADD_FAILURE() << "case " << i << ": " << what << "\n  " << describe(c);
            ok = false;
        };
        if (gpu.box != cpu.box) fail(nbvh::strfmt("box hit gpu %d cpu %d", gpu.box, cpu.box));
        if (gpu.tri != cpu.tri) fail(nbvh::strfmt("triangle hit gpu %d cpu %d", gpu.tri, cpu.tri));
        if (gpu.box && cpu.box && (!t_close(gpu.t_near, cpu.t_near, scale) || !t_close(gpu.t_far, cpu.t_far, scale)))
            fail(nbvh::strfmt("box interval gpu [%.9g, %.9g] cpu [%.9g, %.9g]", gpu.t_near, gpu.t_far, cpu.t_near,
                              cpu.t_far));
        if (gpu.tri && cpu.tri) {
            if (!t_close(gpu.t, cpu.t, scale)) fail(nbvh::strfmt("t gpu %.9g cpu %.9g", gpu.t, cpu.t));
            if (std::fabs(gpu.u - cpu.u) > ABS_UV || std::fabs(gpu.v - cpu.v) > ABS_UV)
                fail(nbvh::strfmt("uv gpu (%g, %g) cpu (%g, %g)", gpu.u, gpu.v, cpu.u, cpu.v));
            if (cpu.t != 0.0f) worst_t = std::max(worst_t, std::fabs(gpu.t - cpu.t) / std::max(std::fabs(cpu.t), scale));
        }
        // Conservative boxes: a box that bounds the triangle is hit whenever the triangle is.
        if (c.tight_box && cpu.tri && !cpu.box) fail("cpu: triangle hit but its bounding box missed");
        if (c.tight_box && gpu.tri && !gpu.box) fail("gpu: triangle hit but its bounding box missed");
        box_hits += cpu.box;
        tri_hits += cpu.tri;
        failures += !ok;
    }
    std::printf("%zu cases: %d box hits, %d triangle hits, worst relative t difference %.3g\n", cases.size(),
                box_hits, tri_hits, double(worst_t));
    // The case mix must exercise both outcomes of both tests.
    EXPECT_GT(box_hits, int(cases.size() / 10));
    EXPECT_LT(box_hits, int(cases.size()));
    EXPECT_GT(tri_hits, int(cases.size() / 10));
    EXPECT_LT(tri_hits, int(cases.size()));
}

// Watertightness on the GPU: a ray aimed at a point of the edge shared by two triangles hits at least
// one of them (grazing cases come in pairs sharing edge (b, d); the ray of modes 1 aims at that edge).
TEST(VkIntersect, SharedEdgeIsWatertight) {
    Cases gen;
    gen.grazing(1.0f, vec3(0.0f), 400, "edge");
    gen.grazing(1e5f, vec3(0.0f), 200, "edge");
    gen.grazing(1.0f, vec3(1e4f, -2e4f, 3e4f), 200, "edge");
    KernelRunner run;
    Buffer in = run.input(pack(gen.all), "cases");
    Buffer out = run.output<uint32_t>(gen.all.size() * NB_IC_OUT, "results");
    struct {
        uint32_t count;
    } push{uint32_t(gen.all.size())};
    run.dispatch({.shader = "tests/intersect.comp", .bindings = {&in, &out}, .items = gen.all.size(),
                  .group_size = 64, .push = push_bytes(push)});
    std::vector<uint32_t> w = run.read<uint32_t>(out, gen.all.size() * NB_IC_OUT);
    int checked = 0, leaks = 0;
    for (size_t pair = 0; pair + 1 < gen.all.size(); pair += 2) {
        if ((pair / 2) % 4 != 1) continue; // mode 1: aimed at a point of the shared edge
        const Case& c = gen.all[pair];
        // The two triangles form a (planar) parallelogram, so a ray aimed at a point of the shared
        // edge (rounded to float) lies inside one of them or on the edge: it must hit at least one.
        bool hit = w[pair * NB_IC_OUT + NB_IC_TRI_HIT] || w[(pair + 1) * NB_IC_OUT + NB_IC_TRI_HIT];
        ++checked;
        if (!hit) {
            ++leaks;
            if (leaks <= 5) ADD_FAILURE() << "ray through a shared edge missed both triangles: " << describe(c);
        }
    }
    EXPECT_GT(checked, 100);
    EXPECT_EQ(leaks, 0);
    EXPECT_EQ(run.validation_messages(), 0);
}
