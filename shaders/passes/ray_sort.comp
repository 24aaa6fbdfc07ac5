// Ray order of the classical traversal and shadow passes (shared/wavefront_gpu.h NB_RS_*), after
// passes/queue_args.comp turned the queue's bin counts into offsets: each ray takes the next position of
// its bin, and the order array maps that position to the ray. pc.mode NB_ARGS_MODE_RAYS: path-ray queue
// pc.in_queue (order at rs_order[0..]); NB_ARGS_MODE_SHADOW: the shadow queue (rs_order[capacity..]).
// Dispatched indirectly over the queue, like the pass it orders.
#version 460
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_vote : require
#include "lib/bindings.glsl"

layout(local_size_x = NB_WAVEFRONT_GROUP) in;

// The next position of bin counter `counter` for this ray. Pixel-major slots put a pixel's samples side
// by side, and their rays (shadow rays above all) often share a bin: one atomic per lane serialises on
// the counter, so when every active lane of the subgroup has the same counter, one atomic takes the
// whole block and each lane its rank in it. Lanes of several bins keep one atomic each: a loop serving
// one bin per round, with its ballot in divergent control flow, lost rays on lavapipe (Mesa 22.3).
uint nb_rs_take(uint counter) {
    if (subgroupAllEqual(counter)) {
        uvec4 lanes = subgroupBallot(true);
        uint rank = subgroupBallotExclusiveBitCount(lanes);
        uint base = 0u;
        if (rank == 0u) base = atomicAdd(rs_bins[counter], subgroupBallotBitCount(lanes));
        return subgroupBroadcastFirst(base) + rank;
    }
    return atomicAdd(rs_bins[counter], 1u);
}

void main() {
    uint k = gl_GlobalInvocationID.x;
    if (pc.mode == NB_ARGS_MODE_RAYS) {
        uint q = pc.in_queue;
        if (k >= queue_count(q)) return;
        uint pos = nb_rs_take(NB_RS_PATH_BINS(q) + nb_rs_bin(ray_load3(q, NB_RAY_ORIGIN, k), ray_load3(q, NB_RAY_DIR, k)));
        if (pos < queue_count(q)) rs_order[pos] = k; // always (shade counted the same keys); memory-safe
    } else {
        if (k >= counters.shadow_count) return;
        uint pos = nb_rs_take(NB_RS_SHADOW_BINS + nb_rs_bin(shadow_load3(NB_SHADOW_ORIGIN, k), shadow_load3(NB_SHADOW_DIR, k)));
        if (pos < counters.shadow_count) rs_order[ray_capacity() + pos] = k;
    }
}
