// The ray-sort key (shaders/shared/wavefront_gpu.h nb_rs_key) on lavapipe against the C++ build of the
// same header: the passes that count and scatter a ray (shade.comp, ray_sort.comp) compute it with
// NB_PRECISE arithmetic, and the host's tests of its levels and cells hold for the shader only if both
// builds agree. Cases: direction level borders (components of +-0.5 and 0 of the unit vector, -0),
// unnormalised, zero, infinite and NaN directions, origins on cell faces, outside the bounds and NaN, flat
// bounds, tiny and huge scenes far from the origin, and random rays.
#include "engine/vk/kernel_runner.h"
#include "shaders/shared/wavefront_gpu.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <vector>

using namespace nbvh::vk;

namespace {

struct Push {
    uint count;
};

TEST(RaySortKeyKernel, MatchesTheCpu) {
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    std::vector<vec3> cases; // origin, direction, lo, hi
    auto add = [&](vec3 o, vec3 d, vec3 lo, vec3 hi) { cases.insert(cases.end(), {o, d, lo, hi}); };
    const vec3 lo(-2.0f, 0.0f, 5.0f), hi(6.0f, 1.0f, 9.0f);
    const vec3 dirs[] = {vec3(1.0f, 0.0f, 0.0f),
                         vec3(-1.0f, 0.0f, 0.0f),
                         vec3(-0.0f, 1.0f, 0.0f),
                         vec3(0.5f, std::sqrt(0.75f), 0.0f),
                         vec3(-0.5f, 0.0f, std::sqrt(0.75f)),
                         vec3(1.0f, 1.0f, 1.0f),
                         vec3(3.0f, -4.0f, 12.0f),
                         vec3(1e-30f, 2e-30f, -1e-30f),
                         vec3(1e30f, -1e30f, 0.0f),
                         vec3(0.0f),
                         vec3(inf, 0.0f, 0.0f),
                         vec3(nan, 1.0f, 0.0f)};
    for (const vec3& d : dirs)
        for (uint i = 0; i <= 8; ++i) { // the cell faces, the bounds' faces and beyond
            const float s = float(i) / 8.0f;
            add(lo + (hi - lo) * s, d, lo, hi);
            add(lo + (hi - lo) * vec3(s, 1.0f - s, 0.5f), d, lo, hi);
        }
    add(vec3(nan, 0.5f, -inf), vec3(1.0f), lo, hi);
    add(vec3(-5.0f), vec3(1.0f), lo, hi);
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1.2f, 1.2f);
    for (float scale : {1e-4f, 1.0f, 1e4f})
        for (vec3 offset : {vec3(0.0f), vec3(3e4f, -2e4f, 1e4f)}) {
            const vec3 blo = offset, bhi = offset + vec3(scale, 0.0f, 2.0f * scale); // flat in y
            for (int i = 0; i < 300; ++i)
                add(blo + vec3(u(rng), u(rng), u(rng)) * vec3(scale, scale, 2.0f * scale),
                    vec3(u(rng), u(rng), u(rng)), blo, bhi);
        }
    const size_t n = cases.size() / 4;
    KernelRunner run;
    Buffer in = run.input(cases);
    Buffer out = run.output<uint>(n);
    run.dispatch({.shader = "tests/rs_key.comp",
                  .bindings = {&in, &out},
                  .items = n,
                  .group_size = 64,
                  .push = push_bytes(Push{uint(n)})});
    const std::vector<uint> gpu = run.read<uint>(out, n);
    for (size_t c = 0; c < n; ++c) {
        const vec3* k = &cases[4 * c];
        EXPECT_EQ(gpu[c], nb_rs_key(k[0], k[1], k[2], k[3]))
            << "case " << c << ": origin (" << k[0].x << ", " << k[0].y << ", " << k[0].z << "), direction ("
            << k[1].x << ", " << k[1].y << ", " << k[1].z << ")";
    }
    EXPECT_EQ(run.validation_messages(), 0);
}

} // namespace
