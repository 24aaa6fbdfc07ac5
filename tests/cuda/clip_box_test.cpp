// The CUDA sampler's ray/box clip against the CPU's, bit for bit, on hard cases (numerics rule): axis-
// parallel rays (+0 and -0 components), origins on a slab face, rays through an edge or corner (entry ==
// exit), flat and empty boxes, non-finite coordinates, denormal and huge direction components, tiny boxes
// far from the origin and huge boxes, plus random rays. Same hit/miss, entry and exit, or the two backends
// would train different first leaves for one seed. Skips without a GPU.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "tests/cuda/clip_box_kernels.h"
#include "tests/cuda/cuda_test_support.h"
#include "trainer/cuda/cut_tree.h"
#include "trainer/training_rays.h"

namespace nbvh {
namespace {

test::ClipCase make_case(glm::vec3 lo, glm::vec3 hi, glm::vec3 o, glm::vec3 d, float dilation) {
    test::ClipCase c{};
    for (int k = 0; k < 3; ++k) {
        c.box[k] = lo[k];
        c.box[3 + k] = hi[k];
        c.origin[k] = o[k];
        c.dir[k] = d[k];
    }
    c.dilation = dilation;
    return c;
}

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }

std::vector<test::ClipCase> hard_cases() {
    std::vector<test::ClipCase> v;
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    const glm::vec3 lo(-1.0f, -2.0f, -0.5f), hi(1.0f, 2.0f, 0.5f);
    for (float dil : {1e-5f, 5.5e-5f, 1.1e-4f}) {
        // Axis-parallel rays, +0 and -0 components, origins inside, outside and on the faces.
        for (float z : {0.0f, -0.0f})
            for (float ox : {-1.0f, 1.0f, 0.3f, -1.0001f, 1.00011f, 5.0f}) {
                v.push_back(make_case(lo, hi, {ox, -7.0f, 0.1f}, {z, 1.0f, z}, dil));
                v.push_back(make_case(lo, hi, {ox, 0.0f, -3.0f}, {z, z, -1.0f}, dil));
                v.push_back(make_case(lo, hi, {-9.0f, 0.5f, ox * 0.5f}, {1.0f, z, z}, dil));
            }
        // Through an edge and a corner (entry == exit after the dilation, or a near miss).
        v.push_back(make_case(lo, hi, {-3.0f, -4.0f, 0.0f}, {1.0f, 1.0f, 0.0f}, dil));
        v.push_back(make_case(lo, hi, {-2.0f, -3.0f, -1.5f}, {1.0f, 1.0f, 1.0f}, dil));
        // Flat (zero-thickness) boxes on each axis, grazing and crossing.
        for (int a = 0; a < 3; ++a) {
            glm::vec3 flo = lo, fhi = hi;
            flo[a] = fhi[a] = 0.25f;
            glm::vec3 d(0.3f, -0.2f, 0.9f), o(0.1f, 0.2f, -4.0f);
            v.push_back(make_case(flo, fhi, o, glm::normalize(d), dil));
            glm::vec3 dg = d;
            dg[a] = 0.0f;
            glm::vec3 og = o;
            og[a] = 0.25f;
            v.push_back(make_case(flo, fhi, og, dg, dil)); // in the plane of the flat box
        }
        // Empty and non-finite boxes.
        v.push_back(make_case({1.0f, 0.0f, 0.0f}, {-1.0f, 1.0f, 1.0f}, {0.0f, 0.5f, -3.0f}, {0.0f, 0.0f, 1.0f}, dil));
        v.push_back(make_case({-inf, -1.0f, -1.0f}, {1.0f, 1.0f, 1.0f}, {0.0f, 0.0f, -3.0f}, {0.0f, 0.0f, 1.0f}, dil));
        v.push_back(make_case({-1.0f, nan, -1.0f}, {1.0f, 1.0f, 1.0f}, {0.0f, 0.0f, -3.0f}, {0.0f, 0.0f, 1.0f}, dil));
        // Denormal, tiny and huge direction components (1/d overflows to inf or is huge).
        for (float tiny : {1e-40f, -1e-40f, 1e-30f, 3e-39f})
            v.push_back(make_case(lo, hi, {0.2f, -5.0f, 0.1f}, {tiny, 1.0f, -tiny}, dil));
        v.push_back(make_case(lo, hi, {0.2f, -5.0f, 0.1f}, {1e30f, 1e30f, 0.0f}, dil));
        // A 1 mm box 1e5 from the origin, and a 1e4 box.
        const glm::vec3 far(1e5f, -1e5f, 3e4f);
        for (int k = 0; k < 8; ++k) {
            const glm::vec3 d = glm::normalize(glm::vec3(0.3f + 0.1f * k, 1.0f, -0.2f * k));
            v.push_back(make_case(far - 5e-4f, far + 5e-4f, far - d * 0.01f, d, dil));
            v.push_back(make_case(glm::vec3(-5e3f), glm::vec3(5e3f), glm::vec3(-9e3f, 2.0f * k, 7.0f), d, dil));
        }
    }
    // For the branch-free clip: the smallest normal direction components (1/d near its largest finite
    // value), origins on the box's faces and just outside them with either sign of d, boxes at the
    // loader's 1e9 limit, and a flat box at -0 seen from +0 along -x (slab distances +0 and -0: the one
    // place clip_regular's entry and exit differ from the CPU's in sign, both 0).
    for (float dil : {1e-5f, 1.1e-4f}) {
        v.push_back(make_case({-0.0f, -1.0f, -1.0f}, {-0.0f, 1.0f, 1.0f}, {0.0f, 0.2f, -0.3f},
                              glm::normalize(glm::vec3(-1.0f, 0.1f, 0.2f)), dil));
        for (float s : {1.17549435e-38f, -1.17549435e-38f, 2.5e-38f})
            v.push_back(make_case(lo, hi, {0.2f, -5.0f, 0.1f}, {s, 1.0f, -s}, dil));
        for (float sx : {1.0f, -1.0f})
            for (float ox : {-1.0f, 1.0f}) {
                v.push_back(
                    make_case(lo, hi, {ox, 0.5f, 0.1f}, glm::normalize(glm::vec3(sx, 0.3f, -0.2f)), dil));
                v.push_back(make_case(lo, hi, {ox * 1.00001f, 2.0f, 0.5f},
                                      glm::normalize(glm::vec3(sx, -1.0f, -0.5f)), dil));
            }
        const glm::vec3 big(1e9f, -1e9f, 5e8f);
        for (int k = 0; k < 4; ++k) {
            const glm::vec3 d = glm::normalize(glm::vec3(1.0f - 0.5f * k, -0.3f, 0.2f * k + 0.1f));
            v.push_back(make_case(big - 0.5f, big + 0.5f, big - d * 3.0f, d, dil));
            v.push_back(
                make_case(glm::vec3(-1e9f), glm::vec3(1e9f), glm::vec3(-1.4e9f, 3.0f * k, -7.0f), d, dil));
        }
    }
    // Random rays and boxes at unit scale (the sampler's distribution: origins in a 1.5x box, unit dirs).
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), dl(1e-5f, 1.1e-4f);
    for (int k = 0; k < 20000; ++k) {
        const glm::vec3 c(u(rng), u(rng), u(rng)), e(0.1f + std::fabs(u(rng)), 0.1f + std::fabs(u(rng)),
                                                     0.1f + std::fabs(u(rng)));
        const glm::vec3 d = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + glm::vec3(1e-3f));
        v.push_back(make_case(c - e, c + e, 1.5f * glm::vec3(u(rng), u(rng), u(rng)), d, dl(rng)));
    }
    return v;
}

TEST(CudaSamplerClip, MatchesTheCpuClipBitForBit) {
    REQUIRE_GPU();
    std::vector<test::ClipCase> cases = hard_cases();
    const std::vector<test::ClipCase> input = cases;
    ASSERT_EQ(test::clip_on_device(cases), "");
    size_t hits = 0, misses = 0, regular = 0, never = 0, exit_zero = 0;
    for (size_t i = 0; i < cases.size(); ++i) {
        const test::ClipCase& in = input[i];
        Aabb box;
        box.lo = glm::vec3(in.box[0], in.box[1], in.box[2]);
        box.hi = glm::vec3(in.box[3], in.box[4], in.box[5]);
        float t0 = 0.0f, t1 = 0.0f;
        const bool hit = clip_line_to_box(glm::vec3(in.origin[0], in.origin[1], in.origin[2]),
                                          glm::vec3(in.dir[0], in.dir[1], in.dir[2]), dilate_box(box, in.dilation), t0, t1);
        ASSERT_EQ(cases[i].hit != 0u, hit) << "case " << i;
        float c[3], h[3];
        cuda::box_centre_half(in.box, in.box + 3, c, h);
        const cuda::CutBox kind = cuda::classify_cut_box(c, h);
        if (kind == cuda::CutBox::never_crossed) {
            EXPECT_FALSE(hit) << "case " << i << ": the cut tree leaves this box out";
            never++;
        }
        if (cases[i].regular) { // the branch-free clip: the same hit, entry and exit
            regular++;
            ASSERT_EQ(cases[i].hit_regular != 0u, hit) << "case " << i << " (clip_regular)";
            if (hit && t1 != 0.0f) {
                EXPECT_TRUE(same_bits(cases[i].t_entry_regular, t0)) << "case " << i << " (clip_regular)";
                EXPECT_TRUE(same_bits(cases[i].t_exit_regular, t1)) << "case " << i << " (clip_regular)";
            } else if (hit) { // t_exit = +-0: the walk rejects it either way (clip_box.cuh: +-0 ties)
                EXPECT_EQ(cases[i].t_exit_regular, 0.0f) << "case " << i << " (clip_regular)";
                EXPECT_EQ(cases[i].t_entry_regular, t0) << "case " << i << " (clip_regular)";
                exit_zero++;
            }
        }
        if (!hit) {
            misses++;
            continue;
        }
        hits++;
        EXPECT_TRUE(same_bits(cases[i].t_entry, t0)) << "case " << i << ": " << cases[i].t_entry << " vs " << t0;
        EXPECT_TRUE(same_bits(cases[i].t_exit, t1)) << "case " << i << ": " << cases[i].t_exit << " vs " << t1;
    }
    std::printf("%zu cases: %zu hits, %zu misses, all equal to the CPU's bits; %zu through clip_regular (%zu "
                "hits with t_exit = +-0 compared by value), %zu boxes the cut tree leaves out\n",
                cases.size(), hits, misses, regular, exit_zero, never);
    EXPECT_GT(hits, 3000u);
    EXPECT_GT(misses, 3000u);
    EXPECT_GT(regular, 20000u);
    EXPECT_GE(never, 9u);
    EXPECT_GE(exit_zero, 2u);
}

} // namespace
} // namespace nbvh
