// Turns a queue's atomic counter into vkCmdDispatchIndirect arguments (one invocation). Mode rays:
// arguments for path-ray queue pc.in_queue; empties the other queue (the shade pass appends to it) and
// the shadow queue; counts the rays for --stats (also per bounce). Mode shadow: arguments for the shadow queue.
#version 460
#include "lib/bindings.glsl"

layout(local_size_x = 1) in;

uint groups(uint n) { return (n + NB_WAVEFRONT_GROUP - 1u) / NB_WAVEFRONT_GROUP; }

void main() {
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
