// Evaluates the shared quasi-random sampler (shaders/shared/sampling.h nb_qmc_2d and its pieces) on
// one (sample index, seed) case per invocation; tests/vk/qmc_test.cpp compares with the C++ build.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#include "shared/sampling.h"

layout(local_size_x = 64) in;

layout(scalar, binding = 0) readonly buffer Cases { uvec2 cases[]; };  // (sample index, dimension seed)
layout(scalar, binding = 1) writeonly buffer Results { uvec4 results[]; };
layout(push_constant, scalar) uniform Push { uint count; } push;

void main() {
    uint c = gl_GlobalInvocationID.x;
    if (c >= push.count) return;
    uvec2 k = cases[c];
    vec2 u = nb_qmc_2d(k.x, k.y);
    results[c] = uvec4(floatBitsToUint(u.x), floatBitsToUint(u.y), nb_owen_scramble(k.x, k.y),
                       nb_sobol_dim1(k.x));
}
