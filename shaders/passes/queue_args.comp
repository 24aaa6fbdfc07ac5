// Turns a queue's atomic counter into vkCmdDispatchIndirect arguments (invocation 0). Mode rays:
// arguments for path-ray queue pc.in_queue; empties the other queue (the shade pass appends to it) and
// the shadow queue; counts the rays for --stats (also per bounce). Mode shadow: arguments for the shadow
// queue. With the ray order (params.sort_rays, shared/wavefront_gpu.h NB_RS_*) the whole workgroup also
// turns the queue's bin counts into offsets for passes/ray_sort.comp (exclusive scan; camera rays at
// depth 0 are not sorted) and, in mode rays, zeroes the bins the next shade pass counts into (the other
// queue's and the shadow queue's, whose offsets served the previous bounce).
#version 460
#include "lib/bindings.glsl"

layout(local_size_x = NB_RS_SCAN_THREADS) in;

#define NB_RS_PER_THREAD (NB_RS_BINS / NB_RS_SCAN_THREADS)

shared uint s_scan[NB_RS_SCAN_THREADS];

uint groups(uint n) { return (n + NB_WAVEFRONT_GROUP - 1u) / NB_WAVEFRONT_GROUP; }

// Exclusive scan of the NB_RS_BINS counters from word `base` of rs_bins (a multiple of 4), in place
// (whole workgroup): each invocation sums its contiguous range, the workgroup scans the sums, each
// invocation writes its range's offsets. 16-byte loads: a warp's load touches 32 lines either way, and
// the 32768 bins take a quarter of the load instructions.
#define NB_RS_PER_THREAD4 (NB_RS_PER_THREAD / 4u)
void scan_bins(uint base) {
    uint t = gl_LocalInvocationID.x;
    uint first4 = (base + t * NB_RS_PER_THREAD) / 4u;
    uint sum = 0u;
    for (uint j = 0u; j < NB_RS_PER_THREAD4; ++j) {
        uvec4 c = rs_bins4[first4 + j];
        sum += c.x + c.y + c.z + c.w;
    }
    s_scan[t] = sum;
    barrier();
    for (uint d = 1u; d < NB_RS_SCAN_THREADS; d <<= 1u) {
        uint add = t >= d ? s_scan[t - d] : 0u;
        barrier();
        s_scan[t] += add;
        barrier();
    }
    uint offset = s_scan[t] - sum;
    for (uint j = 0u; j < NB_RS_PER_THREAD4; ++j) {
        uvec4 c = rs_bins4[first4 + j];
        uvec4 o;
        o.x = offset;
        o.y = o.x + c.x;
        o.z = o.y + c.y;
        o.w = o.z + c.z;
        offset = o.w + c.w;
        rs_bins4[first4 + j] = o;
    }
}

void zero_bins(uint base) {
    uint first4 = (base + gl_LocalInvocationID.x * NB_RS_PER_THREAD) / 4u;
    for (uint j = 0u; j < NB_RS_PER_THREAD4; ++j) rs_bins4[first4 + j] = uvec4(0u);
}

void main() {
    if (gl_LocalInvocationID.x == 0u) {
        if (pc.mode == NB_ARGS_MODE_RAYS) {
            uint n = queue_count(pc.in_queue);
            counters.ray_dispatch.x = groups(n);
            counters.ray_dispatch.y = 1u;
            counters.ray_dispatch.z = 1u;
            if (pc.in_queue == 0u) counters.ray_count1 = 0u;
            else counters.ray_count0 = 0u;
            counters.shadow_count = 0u;
            counters.pending_count = 0u;
            if (pc.depth == 0u) counters.rays_primary += n;
            else counters.rays_secondary += n;
            counters.rays_by_depth[min(pc.depth, NB_STAT_DEPTHS - 1u)] += n;
        } else {
            uint n = counters.shadow_count;
            counters.shadow_dispatch.x = groups(n);
            counters.shadow_dispatch.y = 1u;
            counters.shadow_dispatch.z = 1u;
            counters.rays_shadow += n;
            counters.shadow_rays_by_depth[min(pc.depth, NB_STAT_DEPTHS - 1u)] += n;
        }
    }
    // Zeroed with the order off too, so that switching it on between renders finds no stale offsets.
    if (pc.mode == NB_ARGS_MODE_RAYS) {
        zero_bins(NB_RS_PATH_BINS(1u - pc.in_queue));
        zero_bins(NB_RS_SHADOW_BINS);
    }
    if (params.sort_rays == 0u) return; // uniform
    if (pc.mode == NB_ARGS_MODE_RAYS) {
        if (pc.depth > 0u) scan_bins(NB_RS_PATH_BINS(pc.in_queue));
    } else {
        scan_bins(NB_RS_SHADOW_BINS);
    }
}
