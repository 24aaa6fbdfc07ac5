// Ray/box and ray/triangle tests shared by every BVH traversal (C++ CPU traversal, GLSL shaders,
// CUDA trainer). Written in the compat.h subset, scalar per axis so that no result depends on how a
// backend's min/max treat NaN (GLSL leaves that undefined).
//
// Conventions:
//   - a ray is org + t * dir; dir need not be normalised (t is in units of |dir|);
//   - inv_dir is nb_safe_inv_dir(dir) or 1/dir with IEEE infinities; a component whose magnitude is
//     >= NB_INF (3.4e38, infinite included) means "the ray is parallel to that slab";
//   - intervals are closed: a hit at exactly tmin or tmax counts;
//   - no function writes NaN for finite inputs (NaN rays are the caller's bug; they never report a hit).
#ifndef NB_INTERSECT_H
#define NB_INTERSECT_H
#include "compat.h"

// Directions whose component magnitude is below this are treated as parallel to that axis.
#define NB_PARALLEL_EPS 1.0e-30f
// Conservative slab test: each axis' entry distance is moved towards -inf and its exit towards +inf
// by this relative amount (about 17 float ulps; pbrt-v4 §6.8.2 uses 2 gamma(3) on the exit only), so
// rounding never makes a ray miss, or a closest-hit traversal cull, a box that tightly bounds a
// triangle the ray hits (grazing rays, face-on flat boxes, coplanar triangles).
#define NB_SLAB_SLACK 2.0e-6f

// Origin of a ray leaving surface point p along unit normal n (turned to the side the ray leaves): offset
// by `epsilon` (GpuFrameParams::ray_epsilon = NB_RAY_EPSILON_SCALE x the scene extent) plus
// NB_RAY_OFFSET_RELATIVE of p's largest coordinate, so the offset stays above the float spacing far from
// the origin. passes/shade.comp and the secondary-ray tests use it.
#define NB_RAY_EPSILON_SCALE 1.0e-5f
#define NB_RAY_OFFSET_RELATIVE 4.0e-6f
NB_FN vec3 nb_ray_offset(vec3 p, vec3 n, float epsilon) {
    float m = max(abs(p.x), max(abs(p.y), abs(p.z)));
    return p + n * (epsilon + NB_RAY_OFFSET_RELATIVE * m);
}

// Reciprocal direction that never divides by zero: components with |d| < NB_PARALLEL_EPS become
// +-NB_INF (a finite float), which nb_intersect_aabb* read as "parallel". Use this on the GPU, where
// division by zero is undefined in Vulkan.
NB_FN vec3 nb_safe_inv_dir(vec3 dir) {
    vec3 r;
    r.x = abs(dir.x) < NB_PARALLEL_EPS ? (dir.x < 0.0f ? -NB_INF : NB_INF) : 1.0f / dir.x;
    r.y = abs(dir.y) < NB_PARALLEL_EPS ? (dir.y < 0.0f ? -NB_INF : NB_INF) : 1.0f / dir.y;
    r.z = abs(dir.z) < NB_PARALLEL_EPS ? (dir.z < 0.0f ? -NB_INF : NB_INF) : 1.0f / dir.z;
    return r;
}

// One slab [lo, hi] on one axis narrows [t_near, t_far]. A parallel ray (|inv| >= NB_INF) keeps the
// interval when its origin lies inside the closed slab (on a face counts, and a flat slab lo == hi
// with the origin in its plane counts) and empties it otherwise. This avoids 0 * inf = NaN, which
// otherwise appears exactly for axis-parallel rays starting on a face or in a flat box's plane.
NB_FN void nb_clip_slab(float o, float inv, float lo, float hi, NB_INOUT(float) t_near, NB_INOUT(float) t_far) {
    // Branch-free (selects only: traversal tests two boxes per node): both distances are computed
    // even for a parallel axis, where inv = +-NB_INF is finite, so they are +-inf or 0, never NaN.
    float t0 = (lo - o) * inv;
    float t1 = (hi - o) * inv;
    // Ternaries instead of min/max: with a NaN (only from a NaN ray) tn <= tf below is false.
    float tn = t0 < t1 ? t0 : t1;
    float tf = t0 < t1 ? t1 : t0;
    bool parallel = abs(inv) >= NB_INF;
    // A parallel axis keeps the interval when the origin lies in the closed slab (a NaN origin does not).
    bool keep = parallel ? (o >= lo && o <= hi) : (tn <= tf);
    // Widen by NB_SLAB_SLACK (multiplicative: infinities stay infinite, never NaN).
    tn = tn * (tn > 0.0f ? (1.0f - NB_SLAB_SLACK) : (1.0f + NB_SLAB_SLACK));
    tf = tf * (tf < 0.0f ? (1.0f - NB_SLAB_SLACK) : (1.0f + NB_SLAB_SLACK));
    t_near = !keep ? NB_INF : (parallel ? t_near : max(t_near, tn));
    t_far = !keep ? -NB_INF : (parallel ? t_far : min(t_far, tf));
}

// Ray/box interval clipped to [tmin, tmax]; tmin may be -NB_INF (the neural query clips a ray to a
// leaf box with tmin = -inf, official notes §1). Returns false (and t_near = NB_INF, t_far = -NB_INF)
// when the box is missed or empty (lo > hi on an axis).
NB_FN bool nb_intersect_aabb_interval(vec3 org, vec3 inv_dir, vec3 lo, vec3 hi, float tmin, float tmax,
                                      NB_OUT(float) t_near, NB_OUT(float) t_far) {
    float tn = tmin;
    float tf = tmax;
    nb_clip_slab(org.x, inv_dir.x, lo.x, hi.x, tn, tf);
    nb_clip_slab(org.y, inv_dir.y, lo.y, hi.y, tn, tf);
    nb_clip_slab(org.z, inv_dir.z, lo.z, hi.z, tn, tf);
    // Written so that a NaN anywhere (from a NaN ray) fails the test.
    bool hit = (tn <= tf) && (lo.x <= hi.x) && (lo.y <= hi.y) && (lo.z <= hi.z);
    t_near = hit ? tn : NB_INF;
    t_far = hit ? tf : -NB_INF;
    return hit;
}

// Ray/box test for traversal: t_near is the entry distance clipped to tmin (tmin when the origin is
// inside), used to order children nearest-first.
NB_FN bool nb_intersect_aabb(vec3 org, vec3 inv_dir, vec3 lo, vec3 hi, float tmin, float tmax, NB_OUT(float) t_near) {
    float t_far;
    return nb_intersect_aabb_interval(org, inv_dir, lo, hi, tmin, tmax, t_near, t_far);
}

// Watertight ray/triangle test (Woop, Benthin, Wald 2013, "Watertight Ray/Triangle Intersection"),
// without the double-precision fallback: an edge function that rounds to zero counts as "on the
// edge" and hits, so rays through a shared edge or vertex hit at least one of the triangles (no
// leaks). Barycentrics: hit point = (1 - u - v) v0 + u v1 + v v2, u, v, u + v in [0, 1].
// Zero-area triangles (cross(v1 - v0, v2 - v0) == 0 exactly, e.g. repeated or exactly collinear
// vertices; the sheared det alone can round to non-zero for those), rays in the triangle's plane
// (det == 0) and zero directions never hit.
// Outputs are written only on a hit; the hit requires tmin <= t <= tmax.
//
// The per-ray part (dominant axis, shear) depends on the direction only: traversal computes it once per
// ray and object space (nb_ray_shear) and tests each triangle with nb_intersect_triangle_sheared.
struct NbRayShear {
    int kx;
    int ky;
    int kz;
    float sx;
    float sy;
    float sz;
};

// Permute so that z is the dominant direction axis; swap x/y to keep the winding when dir.z < 0.
// False for a zero (or NaN) direction, which hits nothing.
NB_FN bool nb_ray_shear(vec3 dir, NB_OUT(NbRayShear) s) {
    vec3 ad = abs(dir);
    int kz = (ad.x > ad.y) ? ((ad.x > ad.z) ? 0 : 2) : ((ad.y > ad.z) ? 1 : 2);
    int kx = (kz == 2) ? 0 : kz + 1;
    int ky = (kx == 2) ? 0 : kx + 1;
    float dz = dir[kz];
    if (dz < 0.0f) { int tmp = kx; kx = ky; ky = tmp; }
    s.kx = kx;
    s.ky = ky;
    s.kz = kz;
    s.sx = dir[kx] / dz;
    s.sy = dir[ky] / dz;
    s.sz = 1.0f / dz;
    return abs(dz) > 0.0f;
}

NB_FN bool nb_intersect_triangle_sheared(vec3 org, NbRayShear s, vec3 v0, vec3 v1, vec3 v2, float tmin, float tmax,
                                         NB_OUT(float) t, NB_OUT(float) u, NB_OUT(float) v) {
    vec3 n = cross(v1 - v0, v2 - v0);
    if (n.x == 0.0f && n.y == 0.0f && n.z == 0.0f) return false;
    int kx = s.kx, ky = s.ky, kz = s.kz;
    float sx = s.sx, sy = s.sy, sz = s.sz;

    // Vertices relative to the origin, sheared so the ray becomes the +z axis.
    vec3 a = v0 - org;
    vec3 b = v1 - org;
    vec3 c = v2 - org;
    float ax = a[kx] - sx * a[kz], ay = a[ky] - sy * a[kz];
    float bx = b[kx] - sx * b[kz], by = b[ky] - sy * b[kz];
    float cx = c[kx] - sx * c[kz], cy = c[ky] - sy * c[kz];

    // Scaled barycentric edge functions: e0 weights v0, e1 weights v1, e2 weights v2.
    float e0 = cx * by - cy * bx;
    float e1 = ax * cy - ay * cx;
    float e2 = bx * ay - by * ax;
    if ((e0 < 0.0f || e1 < 0.0f || e2 < 0.0f) && (e0 > 0.0f || e1 > 0.0f || e2 > 0.0f)) return false;
    float det = e0 + e1 + e2;
    if (!(det != 0.0f)) return false; // degenerate triangle or ray in its plane (NaN fails too)

    float tt = (e0 * (sz * a[kz]) + e1 * (sz * b[kz]) + e2 * (sz * c[kz])) / det;
    if (!(tt >= tmin && tt <= tmax)) return false; // also rejects NaN/overflow
    float inv_det = 1.0f / det;
    t = tt;
    u = clamp(e1 * inv_det, 0.0f, 1.0f);
    v = clamp(e2 * inv_det, 0.0f, 1.0f);
    return true;
}

NB_FN bool nb_intersect_triangle(vec3 org, vec3 dir, vec3 v0, vec3 v1, vec3 v2, float tmin, float tmax,
                                 NB_OUT(float) t, NB_OUT(float) u, NB_OUT(float) v) {
    NbRayShear s;
    if (!nb_ray_shear(dir, s)) return false;
    return nb_intersect_triangle_sheared(org, s, v0, v1, v2, tmin, tmax, t, u, v);
}

// Back face of a single-sided triangle (glTF material doubleSided false: back faces are culled): the ray
// travels along the counter-clockwise normal cross(v1 - v0, v2 - v0), i.e. meets the triangle from behind.
// Use it in object space: a mirroring instance (negative determinant) turns the world-space winding and,
// by glTF 2.0 §3.7.4, the front face with it, so the object-space test needs no determinant.
NB_FN bool nb_back_facing(vec3 v0, vec3 v1, vec3 v2, vec3 dir) { return dot(cross(v1 - v0, v2 - v0), dir) > 0.0f; }

#endif // NB_INTERSECT_H
