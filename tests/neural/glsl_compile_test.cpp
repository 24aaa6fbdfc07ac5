// The neural shared headers are written once for C++, CUDA and GLSL: compile them with glslc
// (#version 460, scalar block layout, fp16 arithmetic types available) through a kernel that calls
// every function, so a C++-only construct slipping into them fails here rather than in a shader PR.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>

#include "tests/support/test_support.h"

TEST(NeuralSharedHeaders, CompileAsGlsl) {
    const auto dir = nbvh::test::temp_dir("neural_glsl_compile");
    const auto src = dir / "neural_headers.comp";
    std::ofstream(src) << R"(#version 460
#extension GL_EXT_scalar_block_layout : require
#extension GL_EXT_shader_explicit_arithmetic_types_float16 : require
#include "shared/hashgrid.h"
#include "shared/mlp.h"
#include "shared/neural_query.h"
layout(local_size_x = 64) in;
layout(scalar, binding = 0) buffer Grid { float16_t grid[]; };
layout(scalar, binding = 1) buffer Levels { GpuHashLevel levels[]; };
layout(scalar, binding = 2) buffer Boxes { GpuEncodingBox boxes[]; };
layout(scalar, binding = 3) buffer Out { float outv[]; };
void main() {
    GpuEncodingBox box = nb_make_encoding_box(vec3(0.0f), vec3(1.0f, 0.0f, 2.0f));
    vec3 p0, p1, p2;
    bool rev = nb_segment_points(boxes[0], vec3(0.0f), vec3(1.0f, 0.0f, 0.0f), -0.5f, 0.5f, p0, p1, p2);
    float acc = 0.0f;
    for (uint l = 0u; l < NB_GRID_MAX_LEVELS; ++l) {
        uvec3 cell; vec3 frac;
        nb_grid_position(levels[l], p1, cell, frac);
        for (uint c = 0u; c < NB_GRID_CORNERS; ++c)
            acc += nb_grid_corner_weight(frac, c) * float(grid[nb_grid_corner_entry(levels[l], cell, c) * NB_GRID_FEATURES]);
    }
    float t;
    bool ok = nb_decode_depth(box, nb_sigmoid(nb_relu(acc)), -0.5f, 0.5f, 1.0f, t);
    vec3 n = nb_decode_normal(acc, 0.5f, 0.25f);
    uint slot = nb_feature_slot(2u, 7u, 3u) + nb_mlp_weight_index(4u, 15u, 63u) + nb_mlp_layer_outputs(0u);
    outv[gl_GlobalInvocationID.x] = t + n.x + float(slot) + (rev ? 1.0f : 0.0f) + (ok ? 1.0f : 0.0f) +
        (nb_decode_visibility(acc, NB_VISIBILITY_THRESHOLD) ? 1.0f : 0.0f) +
        nb_encode_depth_target(box, 0.1f, -0.5f, 0.5f, rev) + float(nb_hash_coherent_prime(1u, 2u, 3u));
}
)";
    const std::string cmd = std::string(NBVH_GLSLC_PATH) + " --target-env=vulkan1.2 -I \"" +
                            (nbvh::test::source_dir() / "shaders").string() + "\" -o \"" +
                            (dir / "out.spv").string() + "\" \"" + src.string() + "\" 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
}
