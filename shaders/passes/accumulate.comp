// Pass 5: adds each pixel's sample radiance of this wave to the film. Non-finite samples are dropped
// and counted (stats: nonfinite_samples) so one bad sample cannot poison a pixel.
#version 460
#include "lib/bindings.glsl"

layout(local_size_x = NB_WAVEFRONT_GROUP) in;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.pixel_count) return;
    vec3 l = sample_radiance[i];
    if (any(isnan(l)) || any(isinf(l))) {
        atomicAdd(counters.nonfinite_samples, 1u);
        return;
    }
    film[pc.pixel_offset + i] += vec4(l, 1.0f);
}
