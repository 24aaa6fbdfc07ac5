// Minimal GLSL-named vector types for CUDA builds of shaders/shared/ (glm does not support CUDA 13).
// Only what the shared headers use; grows with them. Included by compat.h under __CUDACC__ only.
#ifndef NB_CUDA_VEC_H
#define NB_CUDA_VEC_H
#include <cstdint>
#include <cstring>

#define NB_V __host__ __device__ inline

struct vec2 { float x, y; NB_V vec2() : x(0), y(0) {} NB_V explicit vec2(float s) : x(s), y(s) {} NB_V vec2(float a, float b) : x(a), y(b) {} };
struct vec3 {
    float x, y, z;
    NB_V vec3() : x(0), y(0), z(0) {}
    NB_V explicit vec3(float s) : x(s), y(s), z(s) {}
    NB_V vec3(float a, float b, float c) : x(a), y(b), z(c) {}
    NB_V float& operator[](int i) { return (&x)[i]; }
    NB_V float operator[](int i) const { return (&x)[i]; }
};
struct vec4 {
    float x, y, z, w;
    NB_V vec4() : x(0), y(0), z(0), w(0) {}
    NB_V explicit vec4(float s) : x(s), y(s), z(s), w(s) {}
    NB_V vec4(float a, float b, float c, float d) : x(a), y(b), z(c), w(d) {}
    NB_V vec4(vec3 v, float d) : x(v.x), y(v.y), z(v.z), w(d) {}
    NB_V float& operator[](int i) { return (&x)[i]; }
    NB_V float operator[](int i) const { return (&x)[i]; }
};
struct uvec3 {
    uint32_t x, y, z;
    NB_V uvec3() : x(0), y(0), z(0) {}
    NB_V explicit uvec3(uint32_t s) : x(s), y(s), z(s) {}
    NB_V uvec3(uint32_t a, uint32_t b, uint32_t c) : x(a), y(b), z(c) {}
    NB_V explicit uvec3(vec3 v) : x(uint32_t(int(v.x))), y(uint32_t(int(v.y))), z(uint32_t(int(v.z))) {}
    NB_V uint32_t& operator[](int i) { return (&x)[i]; }
    NB_V uint32_t operator[](int i) const { return (&x)[i]; }
};

#define NB_VEC3_BINOP(op)                                                                         \
    NB_V vec3 operator op(vec3 a, vec3 b) { return vec3(a.x op b.x, a.y op b.y, a.z op b.z); }    \
    NB_V vec3 operator op(vec3 a, float s) { return vec3(a.x op s, a.y op s, a.z op s); }         \
    NB_V vec3 operator op(float s, vec3 a) { return vec3(s op a.x, s op a.y, s op a.z); }
NB_VEC3_BINOP(+) NB_VEC3_BINOP(-) NB_VEC3_BINOP(*) NB_VEC3_BINOP(/)
#undef NB_VEC3_BINOP
NB_V vec3 operator-(vec3 a) { return vec3(-a.x, -a.y, -a.z); }
NB_V uvec3 operator+(uvec3 a, uvec3 b) { return uvec3(a.x + b.x, a.y + b.y, a.z + b.z); }

// Scalar min/max(float) and min/max(unsigned) come from CUDA's math_functions.hpp (host + device).
NB_V float clamp(float x, float a, float b) { return fminf(fmaxf(x, a), b); }
NB_V float mix(float a, float b, float t) { return a + (b - a) * t; }
NB_V float fract(float x) { return x - floorf(x); }
NB_V vec3 min(vec3 a, vec3 b) { return vec3(fminf(a.x, b.x), fminf(a.y, b.y), fminf(a.z, b.z)); }
NB_V vec3 max(vec3 a, vec3 b) { return vec3(fmaxf(a.x, b.x), fmaxf(a.y, b.y), fmaxf(a.z, b.z)); }
NB_V vec3 abs(vec3 a) { return vec3(fabsf(a.x), fabsf(a.y), fabsf(a.z)); }
NB_V vec3 floor(vec3 a) { return vec3(floorf(a.x), floorf(a.y), floorf(a.z)); }
NB_V vec3 fract(vec3 a) { return a - floor(a); }
NB_V vec3 mix(vec3 a, vec3 b, float t) { return a + (b - a) * t; }
NB_V vec3 clamp(vec3 x, vec3 a, vec3 b) { return min(max(x, a), b); }
NB_V float dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
NB_V vec3 cross(vec3 a, vec3 b) { return vec3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x); }
NB_V float length(vec3 a) { return sqrtf(dot(a, a)); }
NB_V vec3 normalize(vec3 a) { return a * rsqrtf(dot(a, a)); }
NB_V float inversesqrt(float x) { return rsqrtf(x); }
// memcpy instead of __float_as_uint (device-only): valid in host and device code, compiles to a move.
NB_V uint32_t floatBitsToUint(float x) { uint32_t u; memcpy(&u, &x, 4); return u; }
NB_V float uintBitsToFloat(uint32_t u) { float x; memcpy(&x, &u, 4); return x; }

#undef NB_V
#endif
