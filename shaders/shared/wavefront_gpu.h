// Wavefront path-tracer state shared by host and shaders: the structure-of-arrays ray, hit and
// shadow-ray buffers, the queue counters with their indirect-dispatch arguments, and the per-pass
// push constants. See engine/render/README.md for the pass sequence.
//
// SOA layout: a buffer is one array of 32-bit words; field f of element i with c components lives at
// word  base + f_offset * capacity + i * c + comp  where f_offset counts words of all earlier fields.
// Every element of a field is contiguous, so a pass that reads only directions touches only them.
#ifndef NB_WAVEFRONT_GPU_H
#define NB_WAVEFRONT_GPU_H
#include "compat.h"

// Threads per workgroup of every 1-D pass (indirect dispatch arguments are computed with it). A
// multiple of 32 and of lavapipe's 8; no pass relies on the subgroup size.
#define NB_WAVEFRONT_GROUP 64u

// ---- Path rays (two ping-pong queues of `capacity` rays each) -----------------------------------
// word offsets of each field within one queue (times capacity)
#define NB_RAY_ORIGIN 0u      // vec3 world space
#define NB_RAY_DIR 3u         // vec3 world space, unit length
#define NB_RAY_THROUGHPUT 6u  // vec3 path throughput (already divided by pdfs and RR)
#define NB_RAY_PIXEL 9u       // uint the path's slot in its wave (nb_slot_pixel / nb_slot_sample)
#define NB_RAY_DEPTH 10u      // uint segment index of this ray (0 = camera ray)
#define NB_RAY_RNG 11u        // uint sampler state
#define NB_RAY_PDF 12u        // float solid-angle pdf of the BSDF sample that made this ray; < 0: delta lobe
                              // or camera ray (no MIS on the emitter it hits)
#define NB_RAY_T_RESUME 13u   // float traversal resume distance (neural leaves: ray suspended at a
                              // leaf continues from here after the neural query; 0 otherwise)
#define NB_RAY_WORDS 14u

NB_FN uint nb_ray_word(uint queue, uint field, uint capacity, uint index, uint components) {
    return queue * NB_RAY_WORDS * capacity + field * capacity + index * components;
}

// ---- Closest hits, one per slot of the queue being traced ---------------------------------------
#define NB_HIT_T 0u         // float distance along the ray (NB_INF: miss)
#define NB_HIT_INSTANCE 1u  // uint instance (NB_NO_HIT: miss)
#define NB_HIT_TRIANGLE 2u  // uint global triangle index
#define NB_HIT_BARY 3u      // vec2 barycentrics (u, v) of v1, v2
#define NB_HIT_WORDS 5u
#define NB_NO_HIT 0xFFFFFFFFu

NB_FN uint nb_hit_word(uint field, uint capacity, uint index, uint components) {
    return field * capacity + index * components;
}

// ---- Shadow rays (one queue; at most one per path per bounce) ------------------------------------
#define NB_SHADOW_ORIGIN 0u       // vec3
#define NB_SHADOW_DIR 3u          // vec3 unit length
#define NB_SHADOW_TMAX 6u         // float distance to the light sample (NB_INF: environment)
#define NB_SHADOW_CONTRIB 7u      // vec3 radiance added to the path when unoccluded (MIS-weighted)
#define NB_SHADOW_PIXEL 10u       // uint the path's slot in its wave, as NB_RAY_PIXEL
#define NB_SHADOW_WORDS 11u

// Bit 31 of NB_RAY_DEPTH and of NB_SHADOW_PIXEL: the ray leaves a neural hit seen from behind, of an
// asset with backface_escape (neural_gpu.h): its neural queries skip back-facing hits (neural_query.h
// nb_backface_skip). Depths and slots stay far below 2^31; readers mask the bit off.
#define NB_RAY_BACKFACE_BIT 0x80000000u

NB_FN uint nb_shadow_word(uint field, uint capacity, uint index, uint components) {
    return field * capacity + index * components;
}

// ---- Pending (ray, neural leaf) pairs (neural issue; allocated with a minimal size until then) ----
// A pair as stored: 12 words, so that the passes move it as three 16-byte words (lib/neural_bindings.glsl;
// 13 words at a 52-byte stride took 13 four-byte accesses each way).
struct GpuPendingLeaf {
    // The ray and its group, packed (nb_pair_pack_ray_group): bits 0-26 the ray (a slot in the current
    // path-ray queue, or ray capacity + a shadow-ray slot); bits 27-30 the group: a ray queues up to
    // GpuNeuralParams.leaves_per_round(_camera) pairs per round, contiguously, in key order, and the first one
    // holds their count (its resumed traversal reduces them), the others 0 (nb_pair_group); bit 31
    // (NB_RAY_BACKFACE_BIT) set: the ray's query skips back-facing hits (every pair of the ray).
    uint ray_group;
    uint instance;  // the neural instance
    uint leaf;      // N-BVH leaf index
    float t_enter;  // leaf interval along the ray (world t)
    float t_exit;
    // The last 7 words serve two phases. Queued (by the traversal): the query's inputs, so that the
    // query pass reads them here, in queue order, instead of from the ray queues at scattered slots:
    // t = the ray's bound (path rays: their tmin, NB_RAY_T_RESUME; shadow rays: their tmax), a / b = its
    // world-space origin / direction. Answered (by the query pass, for the resumed traversal): the
    // accepted hit of this pair (t NB_INF: none), a / b = its world-space normal / albedo.
    float t;
    vec3 a;
    vec3 b;
};
NB_STATIC_ASSERT(sizeof(GpuPendingLeaf) == 48, "GpuPendingLeaf layout");
#define NB_PAIR_RAY_BITS 27u
#define NB_PAIR_RAY_MASK ((1u << NB_PAIR_RAY_BITS) - 1u) // rays < 2^27: the wave plan bounds 2 x capacity
// `group`: the group count (< 16), with NB_RAY_BACKFACE_BIT where the ray skips back faces.
NB_FN uint nb_pair_pack_ray_group(uint ray, uint group) {
    return (ray & NB_PAIR_RAY_MASK) | ((group & 0xFu) << NB_PAIR_RAY_BITS) | (group & NB_RAY_BACKFACE_BIT);
}
NB_FN uint nb_pair_ray(uint ray_group) { return ray_group & NB_PAIR_RAY_MASK; }
// The group count with the back-face bit (as packed).
NB_FN uint nb_pair_flagged_group(uint ray_group) {
    return ((ray_group >> NB_PAIR_RAY_BITS) & 0xFu) | (ray_group & NB_RAY_BACKFACE_BIT);
}
NB_FN uint nb_pair_group(uint group) { return group & ~NB_RAY_BACKFACE_BIT; }

// ---- Queue counters and indirect arguments -------------------------------------------------------
struct GpuDispatchArgs {
    uint x, y, z;
};
NB_STATIC_ASSERT(sizeof(GpuDispatchArgs) == 12, "GpuDispatchArgs layout");

#define NB_STAT_DEPTHS 16u // per-bounce ray statistics kept (GpuQueueCounters)

// One buffer (storage + indirect usage). Byte offsets of the dispatch arguments are fixed below so
// the host can pass them to vkCmdDispatchIndirect.
struct GpuQueueCounters {
    GpuDispatchArgs ray_dispatch;    // byte offset 0: groups for the current path-ray queue
    GpuDispatchArgs shadow_dispatch; // byte offset 12
    GpuDispatchArgs pending_dispatch;// byte offset 24 (neural query, later issue)
    uint ray_count0;                 // rays in queue 0
    uint ray_count1;                 // rays in queue 1
    uint shadow_count;
    uint pending_count;
    uint rays_primary;               // statistics (counted on the GPU)
    uint rays_secondary;
    uint rays_shadow;
    uint nonfinite_samples;          // path samples dropped by accumulate because they were NaN/Inf
    // Path rays and shadow rays per bounce (index = depth; the last bucket also counts deeper ones),
    // beside the per-depth pass times of RenderStats.
    uint rays_by_depth[NB_STAT_DEPTHS];
    uint shadow_rays_by_depth[NB_STAT_DEPTHS];
};
NB_STATIC_ASSERT(sizeof(GpuQueueCounters) == 68 + 8 * NB_STAT_DEPTHS, "GpuQueueCounters layout");
// shadow.comp: the occlusion was decided by passes/neural_shadow.comp (hybrid renders).
#define NB_SHADOW_MODE_HYBRID 1u
#define NB_SHADOW_MODE_SORTED 2u // read shadow ray rs_order[capacity + k] (NB_RS_*)
#define NB_TRAVERSE_MODE_SORTED 1u // traverse.comp: read path ray rs_order[k]
#define NB_COUNTERS_RAY_DISPATCH_OFFSET 0u
#define NB_COUNTERS_SHADOW_DISPATCH_OFFSET 12u
#define NB_COUNTERS_PENDING_DISPATCH_OFFSET 24u

// ---- Ray order of the classical traversal and shadow passes (RenderOptions::sort_rays) -------------
// Secondary and shadow rays are incoherent; the traversal and shadow passes visit them bin by bin, bins
// in order of (direction cell: 4 levels per axis of the unit direction, Morton code of the origin's 8^3
// cell in the scene's bounds), so that a warp's rays walk the same BVH nodes. A counting sort per queue:
// shade.comp counts each ray it appends in its queue's bins, queue_args.comp turns the counts into offsets
// (exclusive scan) and zeroes the bins the next shade pass counts into, passes/ray_sort.comp scatters the ray
// indices, and the pass reads ray order[k]. The order within a bin is whatever the atomics give; each ray's
// result goes to its own slot.
#define NB_RS_BINS 32768u       // 2^(6 direction bits + 9 origin bits)
#define NB_RS_SCAN_THREADS 128u // queue_args.comp's workgroup: Vulkan's guaranteed minimum size
// queue_args.comp scans and zeroes each invocation's NB_RS_BINS / NB_RS_SCAN_THREADS bins as uvec4s.
NB_STATIC_ASSERT(NB_RS_BINS % (4u * NB_RS_SCAN_THREADS) == 0u, "ray-sort bins per scan invocation: a multiple of 4");
// Sort binding layout (words): path-queue bins for queue 0 and 1, shadow bins, the scene's world bounds
// (lo.xyz, hi.xyz as floats, written by the host), then the order of the path queue being traced
// (capacity) and of the shadow queue (capacity).
#define NB_RS_PATH_BINS(q) ((q) * NB_RS_BINS)
#define NB_RS_SHADOW_BINS (2u * NB_RS_BINS)
#define NB_RS_BOUNDS (3u * NB_RS_BINS)
#define NB_RS_HEADER_WORDS (3u * NB_RS_BINS + 8u)
// Spreads the low 3 bits of v to bits 0, 3, 6.
NB_FN uint nb_rs_spread3(uint v) { return (v & 1u) | ((v & 2u) << 2u) | ((v & 4u) << 4u); }
// Level 0..3 of a unit direction's component c: [-1, -0.5), [-0.5, 0), [0, 0.5), [0.5, 1]; -0 and NaN
// count as non-negative (level 2), so a level's top bit is the octant's sign bit inverted.
NB_FN uint nb_rs_dir_level(float c) {
    NB_PRECISE float t = (c + 1.0f) * 2.0f;
    if (t >= 0.0f) return uint(min(t, 3.0f));
    return c < 0.0f ? 0u : 2u; // below -1 by rounding: 0; NaN: 2
}
// Bin of a ray with origin o and direction d in a scene with bounds [lo, hi]: the direction's levels in
// the top 6 bits (x lowest), the Morton code (x lowest) of the origin's cell of an 8^3 grid below.
// shade.comp counts a ray in its bin and ray_sort.comp scatters it by the same key, so the arithmetic is
// NB_PRECISE: both passes must get the same bin, whatever their compilers fuse.
NB_FN uint nb_rs_key(vec3 o, vec3 d, vec3 lo, vec3 hi) {
    NB_PRECISE vec3 ext = max(hi - lo, vec3(1e-30f));
    NB_PRECISE vec3 f = (o - lo) / ext * 8.0f;
    // NaN-safe clamps (a NaN coordinate goes to cell 0: defined, and the same in every pass).
    uint cx = uint(f.x >= 0.0f ? min(f.x, 7.0f) : 0.0f);
    uint cy = uint(f.y >= 0.0f ? min(f.y, 7.0f) : 0.0f);
    uint cz = uint(f.z >= 0.0f ? min(f.z, 7.0f) : 0.0f);
    NB_PRECISE vec3 u = d / length(d); // a zero or non-finite direction: NaN components, level 2
    uint dir = nb_rs_dir_level(u.x) | (nb_rs_dir_level(u.y) << 2u) | (nb_rs_dir_level(u.z) << 4u);
    return (dir << 9u) | nb_rs_spread3(cx) | (nb_rs_spread3(cy) << 1u) | (nb_rs_spread3(cz) << 2u);
}

// ---- Push constants (<= 128 bytes, the Vulkan minimum) --------------------------------------------
#define NB_ARGS_MODE_RAYS 0u    // queue_args.comp: arguments for path-ray queue `in_queue`
#define NB_ARGS_MODE_SHADOW 1u  // queue_args.comp: arguments for the shadow queue

struct GpuPassConstants {
    uint in_queue;      // path-ray queue read by this pass (0 or 1)
    uint depth;         // segment index being traced
    uint sample_index;  // sample of the pixel (0 .. spp-1)
    uint pixel_offset;  // first pixel of the current wave
    uint pixel_count;   // pixels in the current wave
    uint mode;          // pass-specific (NB_ARGS_MODE_*, NB_SHADOW_MODE_*)
    uint wave_samples;  // samples per pixel in the current wave (sample_index .. + wave_samples - 1)
};
NB_STATIC_ASSERT(sizeof(GpuPassConstants) == 28, "GpuPassConstants layout");

// A wave traces wave_samples samples of pixel_count consecutive pixels: pixel_count * wave_samples
// paths, one per slot, pixel-major: slot = (pixel - pixel_offset) * wave_samples + (sample -
// sample_index). A pixel's samples are neighbours in the camera-ray queue, so a subgroup's camera rays
// walk the same nodes (H200: the camera bounce's traversal 30-45 % faster than with sample-major slots,
// results/perf/README.md); the image does not depend on the order (every random number is keyed by
// pixel and sample). Small images take several samples
// per wave so the GPU stays full (engine/render/wavefront.cpp).
NB_FN uint nb_slot_pixel(uint slot, uint pixel_offset, uint wave_samples) {
    return pixel_offset + slot / wave_samples;
}
NB_FN uint nb_slot_sample(uint slot, uint sample_index, uint wave_samples) {
    return sample_index + slot % wave_samples;
}

#endif
