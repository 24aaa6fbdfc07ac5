// Set-0 bindings of the neural part of the wavefront renderer (shared/neural_gpu.h NB_BIND_NEURAL_*),
// included after lib/bindings.glsl by every pass that touches neural data. The weight buffer is seen as
// packed fp16 pairs (uint) unless the pass defines NB_NEURAL_MLP_AS_HALF before including this (the
// cooperative-matrix query pass, which reads the transposed copy, NB_BIND_NEURAL_MLP_T, as float16_t).
#ifndef NB_NEURAL_BINDINGS_GLSL
#define NB_NEURAL_BINDINGS_GLSL
#include "shared/hashgrid.h"
#include "shared/neural_gpu.h"

layout(set = 0, binding = NB_BIND_NEURAL_LEVELS, scalar) readonly buffer NeuralLevelBuffer { GpuHashLevel neural_levels[]; };
layout(set = 0, binding = NB_BIND_NEURAL_GRID, scalar) readonly buffer NeuralGridBuffer { uvec2 neural_grid[]; };
#ifdef NB_NEURAL_MLP_AS_HALF
#extension GL_EXT_shader_16bit_storage : require
#extension GL_EXT_shader_explicit_arithmetic_types_float16 : require
layout(set = 0, binding = NB_BIND_NEURAL_MLP_T, scalar) readonly buffer NeuralMlpBuffer { float16_t neural_mlp_h[]; };
#else
layout(set = 0, binding = NB_BIND_NEURAL_MLP, scalar) readonly buffer NeuralMlpBuffer { uint neural_mlp[]; };
#endif
layout(set = 0, binding = NB_BIND_NBVH_NODES, std430) readonly buffer NbvhNodeBuffer { GpuBvhNode nbvh_nodes[]; };
// Object-space bounds of every N-BVH node: lo at 2i, hi at 2i + 1.
layout(set = 0, binding = NB_BIND_NBVH_BOUNDS, scalar) readonly buffer NbvhBoundsBuffer { vec3 nbvh_bounds[]; };
layout(set = 0, binding = NB_BIND_NEURAL_STATE, scalar) buffer NeuralStateBuffer { GpuNeuralRayState neural_state[]; };
layout(set = 0, binding = NB_BIND_NEURAL_PARAMS, scalar) readonly buffer NeuralParamsBuffer { GpuNeuralParams neural_params; };
layout(set = 0, binding = NB_BIND_NEURAL_ASSETS, scalar) readonly buffer NeuralAssetBuffer { GpuNeuralAsset neural_assets[]; };
layout(set = 0, binding = NB_BIND_NEURAL_COUNTERS, scalar) coherent buffer NeuralCountersBuffer { GpuNeuralCounters neural_counters; };

// Slot k of half `half_` of the pending queue (each half holds leaves_per_round pairs per ray).
uint nb_nl_pending_index(uint half_, uint k) { return half_ * ray_capacity() * neural_params.leaves_per_round + k; }

#endif
