// Layout test kernel: invocation i fills element i of every shared struct through the field lists in
// layout_fields.h and stores it to that struct's scalar-layout buffer (binding = its index there).
// tests/vk/layout_test.cpp compares the bytes with the C++ build of the same fill functions.
#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_GOOGLE_include_directive : require

#include "tests/layout_fields.h"

layout(local_size_x = 1) in;

#define NB_LAYOUT_BUFFER(T, b) layout(scalar, binding = b) writeonly buffer Out_##T { T out_##T[]; };
NB_LAYOUT_STRUCTS(NB_LAYOUT_BUFFER)

#define NB_LAYOUT_STORE(T, b) { T s; nb_layout_fill_##T(s, i); out_##T[i] = s; }

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= NB_LAYOUT_ELEMENTS) return;
    NB_LAYOUT_STRUCTS(NB_LAYOUT_STORE)
}
