// Runs the shared ray-box and ray-triangle tests (shaders/shared/intersect.h) on one case per
// invocation; tests/vk/intersect_test.cpp compares with the C++ build of the same header.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#include "shared/intersect.h"
#include "tests/intersect_case.h"

layout(local_size_x = 64) in;

layout(scalar, binding = 0) readonly buffer Cases { float cases[]; };
layout(scalar, binding = 1) writeonly buffer Results { uint results[]; };
layout(push_constant, scalar) uniform Push { uint count; } push;

vec3 load3(uint base, uint field) {
    uint i = base + field;
    return vec3(cases[i], cases[i + 1u], cases[i + 2u]);
}

void main() {
    uint c = gl_GlobalInvocationID.x;
    if (c >= push.count) return;
    uint in_base = c * NB_IC_IN;
    uint out_base = c * NB_IC_OUT;
    vec3 org = load3(in_base, NB_IC_ORG);
    vec3 dir = load3(in_base, NB_IC_DIR);
    float tmin = cases[in_base + NB_IC_TMIN];
    float tmax = cases[in_base + NB_IC_TMAX];

    float t_near, t_far;
    bool box = nb_intersect_aabb_interval(org, nb_safe_inv_dir(dir), load3(in_base, NB_IC_LO),
                                          load3(in_base, NB_IC_HI), tmin, tmax, t_near, t_far);
    results[out_base + NB_IC_BOX_HIT] = box ? 1u : 0u;
    results[out_base + NB_IC_BOX_NEAR] = floatBitsToUint(t_near);
    results[out_base + NB_IC_BOX_FAR] = floatBitsToUint(t_far);

    float t = 0.0f, u = 0.0f, v = 0.0f;
    bool tri = nb_intersect_triangle(org, dir, load3(in_base, NB_IC_V0), load3(in_base, NB_IC_V1),
                                     load3(in_base, NB_IC_V2), tmin, tmax, t, u, v);
    results[out_base + NB_IC_TRI_HIT] = tri ? 1u : 0u;
    results[out_base + NB_IC_TRI_T] = floatBitsToUint(t);
    results[out_base + NB_IC_TRI_U] = floatBitsToUint(u);
    results[out_base + NB_IC_TRI_V] = floatBitsToUint(v);
    results[out_base + 7u] = 0u;
}
