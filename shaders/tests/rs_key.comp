// Evaluates the ray-sort key (shaders/shared/wavefront_gpu.h nb_rs_key, NB_PRECISE arithmetic) on one
// (origin, direction) case per invocation in fixed bounds; tests/vk/rs_key_test.cpp compares with the
// C++ build: shade.comp and ray_sort.comp must bin every ray alike, and the host tests describe them.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#include "shared/wavefront_gpu.h"

layout(local_size_x = 64) in;

layout(scalar, binding = 0) readonly buffer Cases { vec3 cases[]; }; // origin, direction, lo, hi per case
layout(scalar, binding = 1) writeonly buffer Results { uint results[]; };
layout(push_constant, scalar) uniform Push { uint count; } push;

void main() {
    uint c = gl_GlobalInvocationID.x;
    if (c >= push.count) return;
    results[c] = nb_rs_key(cases[4u * c], cases[4u * c + 1u], cases[4u * c + 2u], cases[4u * c + 3u]);
}
