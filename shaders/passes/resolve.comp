// Pass 6: film (sum over samples) -> linear radiance per pixel (mean), read back by the host, which
// writes EXR as is and tone-maps for PNG (engine/render/tonemap.h).
#version 460
#include "lib/bindings.glsl"

layout(local_size_x = NB_WAVEFRONT_GROUP) in;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= params.width * params.height) return;
    vec4 f = film[i];
    output_pixels[i] = vec4(f.xyz / max(f.w, 1.0f), 1.0f);
}
