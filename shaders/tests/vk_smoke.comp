// Smoke kernel of the Vulkan layer tests: out[i] = in[i] * scale + offset for i < count.
#version 460
#extension GL_EXT_scalar_block_layout : require

layout(local_size_x = 64) in;
layout(constant_id = 0) const uint SCALE = 2u;

layout(scalar, binding = 0) readonly buffer Input { uint in_values[]; };
layout(scalar, binding = 1) writeonly buffer Output { uint out_values[]; };
layout(push_constant, scalar) uniform Push {
    uint count;
    uint offset;
} push;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count) return;
    out_values[i] = in_values[i] * SCALE + push.offset;
}
