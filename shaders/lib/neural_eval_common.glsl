// Bindings and push constants shared by the flat-list neural query kernels (passes/neural_eval_*.comp):
// queries in, decoded hits out (shared/neural_gpu.h). Tests cross-check them against the CPU
// reference; the benchmark times them.
#ifndef NB_NEURAL_EVAL_COMMON_GLSL
#define NB_NEURAL_EVAL_COMMON_GLSL
#extension GL_EXT_scalar_block_layout : require
#include "shared/compat.h"
#include "shared/hashgrid.h"
#include "shared/neural_gpu.h"

layout(push_constant, scalar) uniform EvalPushBlock { GpuNeuralEvalPush pc; };
layout(set = 0, binding = NB_NEVAL_BIND_LEVELS, std430) readonly buffer LevelBuffer { uvec4 neural_levels[]; }; // GpuHashLevel
layout(set = 0, binding = NB_NEVAL_BIND_GRID, scalar) readonly buffer GridBuffer { uvec2 neural_grid[]; };
#ifdef NB_GATHER_YPAIR
// The same buffer in 16-byte words, for the y-pair table after the entries (shared/hashgrid.h).
layout(set = 0, binding = NB_NEVAL_BIND_GRID, std430) readonly buffer GridPairs { uvec4 neural_grid_y[]; };
#endif
layout(set = 0, binding = NB_NEVAL_BIND_QUERIES, scalar) readonly buffer QueryBuffer { GpuNeuralQuery queries[]; };
layout(set = 0, binding = NB_NEVAL_BIND_HITS, scalar) writeonly buffer HitBuffer { GpuNeuralHit hits[]; };


// Query i of the list, or a harmless placeholder past its end (the lanes of a partial workgroup still
// run the subgroup-wide gather and MLP).
GpuNeuralQuery nb_eval_query(uint i, bool valid) {
    GpuNeuralQuery q;
    q.origin = vec3(0.0f);
    q.dir = vec3(0.0f, 0.0f, 1.0f);
    q.t_entry = 0.0f;
    q.t_exit = 0.0f;
    if (valid) q = queries[i];
    return q;
}
#endif
