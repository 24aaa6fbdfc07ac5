// The common subset of GLSL, C++ and CUDA that every header in shaders/shared/ is written in.
//
//   GLSL  : GL_core_profile is defined by glslang; the headers are used as they are.
//   C++   : vector types and functions come from glm (same names as GLSL).
//   CUDA  : glm 0.9.9 does not recognise CUDA 13, so a minimal set of vector types lives in
//           cuda_vec.h (only what the shared headers use).
//
// Writing rules for shared headers (see shaders/README.md):
//   - functions: `NB_FN float nb_name(NB_IN(vec3) a, NB_OUT(float) t)`; prefix nb_ for functions,
//     Gpu for structs, NB_ for constants and macros (GLSL has no namespaces);
//   - no pointers, references, templates, overloading on return type, or implicit int<->float;
//   - unsigned literals with a `u` suffix, float literals with a `.` and `f` suffix (`1.0f`: GLSL
//     accepts `f`);
//   - buffers use scalar block layout (GL_EXT_scalar_block_layout): vec3 is 12 bytes everywhere;
//     every struct has a static_assert of its size under NB_CPP.
#ifndef NB_COMPAT_H
#define NB_COMPAT_H

#if defined(GL_core_profile) || defined(GL_es_profile)
#define NB_GLSL 1
#define NB_FN
#define NB_IN(T) in T
#define NB_OUT(T) out T
#define NB_INOUT(T) inout T
#define NB_STATIC_ASSERT(cond, msg)
#define NB_CONST const
// A value that every shader computing it must get to the same bits (no contraction into fma, no
// reassociation): e.g. a ray's sort key, computed by one pass to count and by another to scatter.
#define NB_PRECISE precise

#else // C++ and CUDA
#define NB_CPP 1
#include <cstdint>
#include <cmath>
#if defined(__CUDACC__)
#define NB_CUDA 1
#define NB_FN __host__ __device__ inline
#include "cuda_vec.h"
#else
#define NB_FN inline
#include <glm/glm.hpp>
using glm::vec2; using glm::vec3; using glm::vec4;
using glm::ivec2; using glm::ivec3; using glm::ivec4;
using glm::uvec2; using glm::uvec3; using glm::uvec4;
using glm::mat3; using glm::mat4;
using glm::abs; using glm::clamp; using glm::cross; using glm::dot; using glm::floor; using glm::fract;
using glm::length; using glm::max; using glm::min; using glm::mix; using glm::normalize; using glm::sign;
using glm::sqrt; using glm::exp; using glm::log; using glm::pow; using glm::step;
NB_FN float inversesqrt(float x) { return 1.0f / std::sqrt(x); }
NB_FN uint32_t floatBitsToUint(float x) { uint32_t u; __builtin_memcpy(&u, &x, 4); return u; }
NB_FN float uintBitsToFloat(uint32_t u) { float x; __builtin_memcpy(&x, &u, 4); return x; }
#endif
typedef unsigned int uint;
#define NB_IN(T) T
#define NB_OUT(T) T&
#define NB_INOUT(T) T&
#define NB_STATIC_ASSERT(cond, msg) static_assert(cond, msg)
#define NB_CONST constexpr
#define NB_PRECISE
#endif

// Large finite sentinel for "no hit yet" (a literal: GLSL has no FLT_MAX).
#define NB_INF 3.402823466e+38f

#endif // NB_COMPAT_H
