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

// One slab's [ta, tb] (ta <= tb) narrowing [t0, t1], and the clip's result: a hit when the interval is a
// finite, non-empty one (clip_line_to_box's last steps).
__device__ inline void clip_narrow(float ta, float tb, float& t0, float& t1) {
    t0 = ta > t0 ? ta : t0;
    t1 = tb < t1 ? tb : t1;
}
__device__ inline bool clip_result(float t0, float t1, float& t_entry, float& t_exit) {
    if (!(t0 <= t1) || !isfinite(t0) || !isfinite(t1)) return false;
    t_entry = t0;
    t_exit = t1;
    return true;
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
        clip_narrow(ta, tb, t0, t1);
    }
    return clip_result(t0, t1, t_entry, t_exit);
}

// The same clip for the common case, without its branches: a box the cut tree keeps (cut_tree.h
// classify_cut_box, regular: finite, not empty, |centre| + 2 |half| <= 1e37, so every bound of every dilation
// is finite) and a ray whose direction components are all normal floats (slab_ray_regular: 1/d is finite and
// no axis is parallel). Then clip_dilated never takes its early returns or its parallel-axis branch, and its
// swap is decided by the sign of d alone: for d > 0, lo <= hi gives (lo - o) / d <= (hi - o) / d (rounding is
// monotonic), for d < 0 the reverse. So each axis computes its near bound c - s h (1 + dil) and far bound c +
// s h (1 + dil) with s = sign(d) folded into `gs` (a product by -1 and x - (-y) are exact), the same floats
// as clip_dilated's after its swap: the same hit and the same t_entry and t_exit to the bit
// (tests/cuda/clip_box_test.cpp), with one exception: where an axis's two slab distances are zeros of
// opposite sign, clip_dilated keeps them unswapped and this clip reverses them, so a hit there has entry and
// exit (+0, -0) against (-0, +0). Such a hit has t_exit = 0, which the first-leaf walk rejects (t_exit <=
// min_exit, min_exit > 0: training_asset.cpp), so the walk's results are the same. About half the
// instructions per box (the first-leaf walk clips two child boxes per node).
struct SlabRay {
    float o[3], inv[3], gs[3];
};
__device__ inline bool slab_ray_regular(vec3 d) {
    for (int a = 0; a < 3; ++a)
        if (!(fabsf(d[a]) >= 1.17549435e-38f) || !isfinite(d[a])) return false; // FLT_MIN: normal
    return true;
}
__device__ inline SlabRay slab_ray(vec3 o, vec3 d, const InvDir& id, float dilation) {
    SlabRay r;
    const float grow = 1.0f + dilation;
    for (int a = 0; a < 3; ++a) {
        r.o[a] = o[a];
        r.inv[a] = id.v[a];
        r.gs[a] = d[a] > 0.0f ? grow : -grow;
    }
    return r;
}
__device__ inline bool clip_regular(const float centre[3], const float half_extent[3], const SlabRay& r,
                                    float& t_entry, float& t_exit) {
    float t0 = -NB_INF, t1 = NB_INF;
    for (int a = 0; a < 3; ++a) {
        const float sh = half_extent[a] * r.gs[a];
        const float ta = ((centre[a] - sh) - r.o[a]) * r.inv[a];
        const float tb = ((centre[a] + sh) - r.o[a]) * r.inv[a];
        clip_narrow(ta, tb, t0, t1);
    }
    return clip_result(t0, t1, t_entry, t_exit);
}

} // namespace nbvh::cuda
