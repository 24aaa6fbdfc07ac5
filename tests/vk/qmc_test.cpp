// The quasi-random sampler (shaders/shared/sampling.h nb_qmc_2d) on lavapipe against the C++ build of
// the same header: bit for bit (integer hashing and bit reversal only, then an exact int -> float).
#include "engine/vk/kernel_runner.h"
#include "shaders/shared/sampling.h"

#include <gtest/gtest.h>

#include <vector>

using namespace nbvh::vk;

namespace {

struct Push {
    uint count;
};

TEST(QmcKernel, MatchesTheCpuBitForBit) {
    std::vector<uvec2> cases;
    for (uint seed : {0u, 1u, 0xDEADBEEFu, 0xFFFFFFFFu, nb_qmc_dim_seed(nb_qmc_pixel_seed(7u, 3u), 2u, 4u)})
        for (uint i : {0u, 1u, 2u, 3u, 255u, 256u, 4095u, 65535u, 0x7FFFFFFFu, 0xFFFFFFFFu})
            cases.push_back(uvec2(i, seed));
    for (uint i = 0; i < 1024; ++i) cases.push_back(uvec2(i, nb_pcg_hash(i)));
    KernelRunner run;
    Buffer in = run.input(cases);
    Buffer out = run.output<uvec4>(cases.size());
    run.dispatch({.shader = "tests/qmc.comp",
                  .bindings = {&in, &out},
                  .items = cases.size(),
                  .group_size = 64,
                  .push = push_bytes(Push{uint(cases.size())})});
    const std::vector<uvec4> gpu = run.read<uvec4>(out, cases.size());
    for (size_t c = 0; c < cases.size(); ++c) {
        const vec2 u = nb_qmc_2d(cases[c].x, cases[c].y);
        SCOPED_TRACE(testing::Message() << "index " << cases[c].x << " seed " << cases[c].y);
        EXPECT_EQ(gpu[c].x, floatBitsToUint(u.x));
        EXPECT_EQ(gpu[c].y, floatBitsToUint(u.y));
        EXPECT_EQ(gpu[c].z, nb_owen_scramble(cases[c].x, cases[c].y));
        EXPECT_EQ(gpu[c].w, nb_sobol_dim1(cases[c].x));
    }
    EXPECT_EQ(run.validation_messages(), 0);
}

} // namespace
