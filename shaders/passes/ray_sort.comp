// Ray order of the classical traversal and shadow passes (shared/wavefront_gpu.h NB_RS_*), after
// passes/queue_args.comp turned the queue's bin counts into offsets: each ray takes the next position of
// its bin, and the order array maps that position to the ray. pc.mode NB_ARGS_MODE_RAYS: path-ray queue
// pc.in_queue (order at rs_order[0..]); NB_ARGS_MODE_SHADOW: the shadow queue (rs_order[capacity..]).
// Dispatched indirectly over the queue, like the pass it orders.
#version 460
#include "lib/bindings.glsl"

layout(local_size_x = NB_WAVEFRONT_GROUP) in;

void main() {
    uint k = gl_GlobalInvocationID.x;
    if (pc.mode == NB_ARGS_MODE_RAYS) {
        uint q = pc.in_queue;
        if (k >= queue_count(q)) return;
        uint pos = atomicAdd(rs_bins[NB_RS_PATH_BINS(q) + nb_rs_bin(ray_load3(q, NB_RAY_ORIGIN, k), ray_load3(q, NB_RAY_DIR, k))], 1u);
        if (pos < queue_count(q)) rs_order[pos] = k; // always (shade counted the same keys); memory-safe
    } else {
        if (k >= counters.shadow_count) return;
        uint pos = atomicAdd(rs_bins[NB_RS_SHADOW_BINS + nb_rs_bin(shadow_load3(NB_SHADOW_ORIGIN, k), shadow_load3(NB_SHADOW_DIR, k))], 1u);
        if (pos < counters.shadow_count) rs_order[ray_capacity() + pos] = k;
    }
}
