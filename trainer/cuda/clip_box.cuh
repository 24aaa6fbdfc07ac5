// The training sampler's ray/box clip (trainer/training_rays.cpp clip_line_to_box on a box dilated as
// dilate_box(), the same float operations), for sampling_kernels.cu and its numerics test
// (tests/cuda/clip_box_kernels.cu). Include from .cu files compiled with --fmad=false only: the CPU
// evaluates the same expressions without FMA, and both must draw the same rays.
#pragma once
#include <cuda_runtime.h>

#include "shaders/shared/compat.h" // NB_INF, vec3 (cuda_vec.h)

namespace nbvh::cuda {

// 1 / d per axis, computed once per ray: clip_line_to_box's `1.0f / d` (IEEE division, so the same value
// as dividing per box; 0 where d is 0, which clip_dilated tests before using it).
struct InvDir { float v[3]; };
__device__ inline InvDir inv_dir(vec3 d) {
    InvDir r;
    for (int a = 0; a < 3; ++a) r.v[a] = d[a] != 0.0f ? 1.0f / d[a] : 0.0f;
    return r;
}

// trainer/training_rays.cpp clip_line_to_box on a box dilated as dilate_box() (same float operations),
// the box given by its centre and half extent (cut_tree.h box_centre_half, computed once per node on
// the host: dilate_box's first steps, the same values). A negative half extent is an empty box.
__device__ inline bool clip_dilated(const float centre[3], const float half_extent[3], vec3 o, vec3 d,
                                    const InvDir& id, float dilation, float& t_entry, float& t_exit) {
    float t0 = -NB_INF, t1 = NB_INF;
    const float grow = 1.0f + dilation;
    for (int a = 0; a < 3; ++a) {
        if (half_extent[a] < 0.0f) return false; // empty box (lo > hi)
        const float c = centre[a];
        const float half = half_extent[a] * grow;
        const float lo = c - half, hi = c + half;
        if (!isfinite(lo) || !isfinite(hi)) return false;
        const float oa = o[a], da = d[a];
        if (da == 0.0f) {
            if (oa < lo || oa > hi) return false;
            continue;
        }
        const float inv = id.v[a];
        float ta = (lo - oa) * inv, tb = (hi - oa) * inv;
        if (ta > tb) { const float t = ta; ta = tb; tb = t; }
        t0 = ta > t0 ? ta : t0;
        t1 = tb < t1 ? tb : t1;
    }
    if (!(t0 <= t1) || !isfinite(t0) || !isfinite(t1)) return false;
    t_entry = t0;
    t_exit = t1;
    return true;
}

} // namespace nbvh::cuda
