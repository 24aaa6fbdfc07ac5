// Pass 5: adds each pixel's sample radiance of this wave (pc.wave_samples samples) to the film.
// Non-finite samples are dropped and counted (stats: nonfinite_samples) so one bad sample cannot poison
// a pixel.
#version 460
#include "lib/bindings.glsl"

layout(local_size_x = NB_WAVEFRONT_GROUP) in;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.pixel_count) return;
    vec4 sum = vec4(0.0f);
    uint bad = 0u;
    for (uint s = 0u; s < pc.wave_samples; ++s) {
        vec3 l = sample_radiance[i * pc.wave_samples + s]; // pixel-major slots (shared/wavefront_gpu.h)
        if (any(isnan(l)) || any(isinf(l))) ++bad;
        else sum += vec4(l, 1.0f);
    }
    if (bad != 0u) atomicAdd(counters.nonfinite_samples, bad);
    film[pc.pixel_offset + i] += sum;
}
