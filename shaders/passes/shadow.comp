// Pass 4: any-hit visibility of every shadow ray; an unoccluded ray adds its (MIS-weighted) light
// contribution to its pixel's sample radiance. Only built when the scene has lights to sample.
#version 460
#include "lib/bindings.glsl"
#include "lib/traverse.glsl"

layout(local_size_x = NB_WAVEFRONT_GROUP) in;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= counters.shadow_count) return;
    if ((pc.mode & NB_SHADOW_MODE_SORTED) != 0u) i = rs_order[ray_capacity() + i]; // passes/ray_sort.comp
    float tmax = uintBitsToFloat(shadow_load1(NB_SHADOW_TMAX, i));
    uint slot = shadow_load1(NB_SHADOW_PIXEL, i) & ~NB_RAY_BACKFACE_BIT;
    bool occluded;
    if (NB_HAS_NEURAL && (pc.mode & NB_SHADOW_MODE_HYBRID) != 0u) {
        // Hybrid render: passes/neural_shadow.comp decided (triangles and neural leaves) and marked the
        // occluded rays (nb_shadow_mark_occluded). A renderer with a model switched to its classical
        // reference traces here (engine/render/wavefront.h apply).
        occluded = nb_shadow_is_marked_occluded(tmax);
    } else { // the ray itself is read only where it is traced
        g_alpha_seed = nb_shadow_alpha_seed(slot);
        nb_trace(shadow_load3(NB_SHADOW_ORIGIN, i), shadow_load3(NB_SHADOW_DIR, i), 0.0f, tmax, true);
        occluded = g_hit_instance != NB_NO_HIT;
    }
    if (!occluded) {
        // At most one shadow ray per path per bounce and one slot per path: no write races.
        sample_radiance[slot] += shadow_load3(NB_SHADOW_CONTRIB, i);
    }
}
