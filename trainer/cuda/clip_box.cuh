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

// trainer/training_rays.cpp clip_line_to_box on a box dilated as dilate_box() (same float operations).
__device__ inline bool clip_dilated(const float lo3[3], const float hi3[3], vec3 o, vec3 d, const InvDir& id,
                                    float dilation, float& t_entry, float& t_exit) {
    float t0 = -NB_INF, t1 = NB_INF;
    for (int a = 0; a < 3; ++a) {
        const float blo = lo3[a], bhi = hi3[a];
        if (blo > bhi) return false; // empty box
        const float c = 0.5f * (blo + bhi);
        const float half = 0.5f * (bhi - blo) * (1.0f + dilation);
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
