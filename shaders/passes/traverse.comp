// Pass 2: closest hit of every ray in path-ray queue pc.in_queue through the TLAS and the BLASes
// (lib/traverse.glsl); writes the hit SOA. Dispatched indirectly from the queue's counter.
#version 460
#include "lib/bindings.glsl"
#include "lib/traverse.glsl"

layout(local_size_x = NB_WAVEFRONT_GROUP) in;

void main() {
    uint i = gl_GlobalInvocationID.x;
    uint q = pc.in_queue;
    if (i >= queue_count(q)) return;
    if ((pc.mode & NB_TRAVERSE_MODE_SORTED) != 0u) i = rs_order[i]; // passes/ray_sort.comp
    vec3 org = ray_load3(q, NB_RAY_ORIGIN, i);
    vec3 dir = ray_load3(q, NB_RAY_DIR, i);
    g_alpha_seed = ray_load1(q, NB_RAY_RNG, i);
    float t_resume = uintBitsToFloat(ray_load1(q, NB_RAY_T_RESUME, i));
    g_camera_ray = pc.depth == 0u;
    nb_trace(org, dir, t_resume, NB_INF, false);
    hit_store1(NB_HIT_T, i, floatBitsToUint(g_hit_instance == NB_NO_HIT ? NB_INF : g_tmax));
    hit_store1(NB_HIT_INSTANCE, i, g_hit_instance);
    hit_store1(NB_HIT_TRIANGLE, i, g_hit_triangle);
    hit_store_bary(i, g_hit_bary);
}
