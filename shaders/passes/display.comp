// The viewer's display pass (app/viewer/presenter.cpp): the renderer's linear output pixels -> the
// bytes `nbvh render` would write to a PNG (exposure, tone map, sRGB, 8 bits: shared/display.h), packed
// RGBA8 (alpha 255) for a copy into the window's film image. Replaces a download, a host tone map and
// an upload per frame.
#version 460
#extension GL_EXT_scalar_block_layout : require
#include "shared/display.h"

layout(local_size_x = 256) in; // 2D grid of groups for large windows (app/viewer/display_pass.cpp)

layout(push_constant, scalar) uniform DisplayPush {
    uint pixel_count;
    float scale;    // 2^exposure
    uint tone_map;  // NB_TONE_MAP_*
    uint pad;
} pc;
layout(set = 0, binding = 0, scalar) readonly buffer LinearPixels { vec4 linear_pixels[]; };
layout(set = 0, binding = 1, scalar) writeonly buffer DisplayPixels { uint display_pixels[]; };

void main() {
    uint i = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * 256u + gl_LocalInvocationID.x;
    if (i >= pc.pixel_count) return;
    uvec3 b = nb_display_rgb8(linear_pixels[i].xyz, pc.scale, pc.tone_map);
    display_pixels[i] = b.x | (b.y << 8u) | (b.z << 16u) | (255u << 24u);
}
