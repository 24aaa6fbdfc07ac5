// Record layout of the intersection test kernel (shaders/tests/intersect.comp, tests/vk/
// intersect_test.cpp): flat float/uint arrays, so the test declares no GPU struct of its own.
#ifndef NB_INTERSECT_CASE_H
#define NB_INTERSECT_CASE_H

// Input: NB_IC_IN floats per case.
#define NB_IC_ORG 0u   // vec3 ray origin
#define NB_IC_DIR 3u   // vec3 ray direction (not normalised)
#define NB_IC_TMIN 6u  // float
#define NB_IC_TMAX 7u  // float
#define NB_IC_LO 8u    // vec3 box min
#define NB_IC_HI 11u   // vec3 box max
#define NB_IC_V0 14u   // vec3 triangle vertices
#define NB_IC_V1 17u
#define NB_IC_V2 20u
#define NB_IC_IN 24u

// Output: NB_IC_OUT 32-bit words per case (floats stored as their bits).
#define NB_IC_BOX_HIT 0u  // uint 0/1: nb_intersect_aabb_interval
#define NB_IC_BOX_NEAR 1u // float t_near
#define NB_IC_BOX_FAR 2u  // float t_far
#define NB_IC_TRI_HIT 3u  // uint 0/1: nb_intersect_triangle
#define NB_IC_TRI_T 4u    // float t, u, v (0 when missed)
#define NB_IC_TRI_U 5u
#define NB_IC_TRI_V 6u
#define NB_IC_OUT 8u

#endif
