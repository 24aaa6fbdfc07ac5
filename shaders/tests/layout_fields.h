// Field lists of every GPU-shared struct, for the layout test (tests/vk/layout_test.cpp with
// shaders/tests/layout.comp). Included by both: the shader fills each struct through these lists and
// writes it to a scalar-layout buffer; the C++ build fills the same struct with the same values, and
// the test compares the two field by field (by name) and byte by byte. A field whose GLSL offset
// differs from its C++ offset, a wrong struct size (array stride) or a field missing from a list shows
// up as a named mismatch.
//
// To add a struct GpuFoo from shaders/shared/foo.h:
//   1. include foo.h below;
//   2. write NB_LAYOUT_FIELDS_GpuFoo(F) listing EVERY field as F(name) (nested struct members as
//      F(inner.member), array elements as F(arr[0]) F(arr[1]) ...);
//   3. add S(GpuFoo, <next binding>) to NB_LAYOUT_STRUCTS.
// Supported field types: float, int, uint, vec2-4, ivec2-4, uvec2-4 (add an nb_lv overload for more).
#ifndef NB_LAYOUT_FIELDS_H
#define NB_LAYOUT_FIELDS_H
#include "../shared/compat.h"
#include "../shared/bvh_node.h"
#include "../shared/wide_bvh_node.h"
#include "../shared/hashgrid.h"
#include "../shared/neural_query.h"
#include "../shared/scene_gpu.h"
#include "../shared/wavefront_gpu.h"
#include "../shared/neural_gpu.h"

// --- every struct (name, binding in layout.comp) ------------------------------------------------
#define NB_LAYOUT_STRUCTS(S) \
    S(GpuBvhNode, 0)         \
    S(GpuHashLevel, 1)       \
    S(GpuEncodingBox, 2)     \
    S(GpuInstance, 3)        \
    S(GpuTriangle, 4)        \
    S(GpuVertex, 5)          \
    S(GpuTexRef, 6)          \
    S(GpuMaterial, 7)        \
    S(GpuTextureInfo, 8)     \
    S(GpuLight, 9)           \
    S(GpuFrameParams, 10)    \
    S(GpuPendingLeaf, 11)    \
    S(GpuDispatchArgs, 12)   \
    S(GpuQueueCounters, 13)  \
    S(GpuPassConstants, 14)  \
    S(GpuNeuralQuery, 15)    \
    S(GpuNeuralHit, 16)      \
    S(GpuNeuralEvalPush, 17) \
    S(GpuNeuralRayState, 18) \
    S(GpuNeuralParams, 19)   \
    S(GpuNeuralCounters, 20) \
    S(GpuNeuralAsset, 21)    \
    S(GpuWideNode, 22)

// --- field lists ---------------------------------------------------------------------------------
#define NB_LAYOUT_FIELDS_GpuBvhNode(F) \
    F(lmin) F(left) F(lmax) F(right) F(rmin) F(pad0) F(rmax) F(pad1)
#define NB_LAYOUT_FIELDS_GpuWideNode(F) \
    F(origin) F(child0) F(scale) F(child1) F(qlo_x) F(qlo_y) F(qlo_z) F(child2) F(qhi_x) F(qhi_y) F(qhi_z) F(child3)
#define NB_LAYOUT_FIELDS_GpuHashLevel(F) \
    F(offset) F(size) F(resolution) F(scale) F(hashed) F(pad0) F(pad1) F(pad2)
#define NB_LAYOUT_FIELDS_GpuEncodingBox(F) \
    F(center) F(depth_pad) F(extent) F(fixed_depth_eps)
#define NB_LAYOUT_FIELDS_GpuInstance(F)                                                           \
    F(object_to_world[0]) F(object_to_world[1]) F(object_to_world[2])                             \
    F(world_to_object[0]) F(world_to_object[1]) F(world_to_object[2])                             \
    F(blas_root) F(first_triangle) F(kind) F(mesh)
#define NB_LAYOUT_FIELDS_GpuTriangle(F) F(v0) F(v1) F(v2) F(material)
#define NB_LAYOUT_FIELDS_GpuVertex(F) F(position) F(u0) F(normal) F(v0) F(tangent) F(uv1)
#define NB_LAYOUT_FIELDS_GpuTexRef(F) F(texture) F(uv_set) F(row0) F(row1)
#define NB_LAYOUT_TEXREF(F, t) F(t.texture) F(t.uv_set) F(t.row0) F(t.row1)
#define NB_LAYOUT_FIELDS_GpuMaterial(F)                                                           \
    F(base_color) F(emissive) F(metallic) F(roughness) F(normal_scale) F(alpha_cutoff)            \
    F(transmission) F(alpha_mode) F(double_sided) F(pad0) F(pad1)                                \
    NB_LAYOUT_TEXREF(F, base_color_tex) NB_LAYOUT_TEXREF(F, metallic_roughness_tex)              \
    NB_LAYOUT_TEXREF(F, normal_tex) NB_LAYOUT_TEXREF(F, emissive_tex)
#define NB_LAYOUT_FIELDS_GpuTextureInfo(F) F(offset) F(width) F(height) F(pad)
#define NB_LAYOUT_FIELDS_GpuLight(F) F(p0) F(instance) F(p1) F(triangle) F(p2) F(area) F(kind) F(side) F(spot_scale) F(spot_offset)
#define NB_LAYOUT_FIELDS_GpuFrameParams(F)                                                        \
    F(cam_eye) F(cam_tan_half_fov) F(cam_forward) F(aspect) F(cam_right) F(width) F(cam_up)       \
    F(height) F(env_width) F(env_height) F(env_intensity) F(env_rotation) F(env_inv_mean)         \
    F(light_count) F(light_total_power) F(max_depth) F(rr_start_depth) F(seed) F(spp)             \
    F(wave_capacity) F(ray_epsilon) F(instance_count) F(punctual_count) F(sort_rays)  \
    F(path_sampler) F(pad0) F(pad1) F(pad2)
#define NB_LAYOUT_FIELDS_GpuPendingLeaf(F)                                                                   \
    F(ray_group) F(instance) F(leaf) F(t_enter) F(t_exit) F(t) F(a) F(b)
#define NB_LAYOUT_FIELDS_GpuDispatchArgs(F) F(x) F(y) F(z)
#define NB_LAYOUT_FIELDS_GpuQueueCounters(F)                                                      \
    F(ray_dispatch.x) F(ray_dispatch.y) F(ray_dispatch.z)                                         \
    F(shadow_dispatch.x) F(shadow_dispatch.y) F(shadow_dispatch.z)                                \
    F(pending_dispatch.x) F(pending_dispatch.y) F(pending_dispatch.z)                             \
    F(ray_count0) F(ray_count1) F(shadow_count) F(pending_count) F(rays_primary)                  \
    F(rays_secondary) F(rays_shadow) F(nonfinite_samples) \
    F(rays_by_depth[0]) F(rays_by_depth[1]) F(rays_by_depth[2]) F(rays_by_depth[3]) \
    F(rays_by_depth[4]) F(rays_by_depth[5]) F(rays_by_depth[6]) F(rays_by_depth[7]) \
    F(rays_by_depth[8]) F(rays_by_depth[9]) F(rays_by_depth[10]) F(rays_by_depth[11]) \
    F(rays_by_depth[12]) F(rays_by_depth[13]) F(rays_by_depth[14]) F(rays_by_depth[15]) \
    F(shadow_rays_by_depth[0]) F(shadow_rays_by_depth[1]) F(shadow_rays_by_depth[2]) F(shadow_rays_by_depth[3]) \
    F(shadow_rays_by_depth[4]) F(shadow_rays_by_depth[5]) F(shadow_rays_by_depth[6]) F(shadow_rays_by_depth[7]) \
    F(shadow_rays_by_depth[8]) F(shadow_rays_by_depth[9]) F(shadow_rays_by_depth[10]) F(shadow_rays_by_depth[11]) \
    F(shadow_rays_by_depth[12]) F(shadow_rays_by_depth[13]) F(shadow_rays_by_depth[14]) F(shadow_rays_by_depth[15])
#define NB_LAYOUT_FIELDS_GpuPassConstants(F)                                                      \
    F(in_queue) F(depth) F(sample_index) F(pixel_offset) F(pixel_count) F(mode) F(wave_samples)
#define NB_LAYOUT_FIELDS_GpuNeuralQuery(F) F(origin) F(t_entry) F(dir) F(t_exit)
#define NB_LAYOUT_FIELDS_GpuNeuralHit(F) \
    F(normal) F(t) F(albedo) F(visibility) F(depth) F(flags) F(pad0) F(pad1)
#define NB_LAYOUT_FIELDS_GpuNeuralEvalPush(F) \
    F(box.center) F(box.depth_pad) F(box.extent) F(box.fixed_depth_eps) F(count) F(threshold) F(first) F(pad1)
#define NB_LAYOUT_FIELDS_GpuNeuralRayState(F)                                                     \
    F(normal) F(best_t) F(albedo_rg) F(albedo_b) F(hit_leaf) F(instance) F(key_t) F(key_instance)    \
    F(key_leaf) F(status)                                                                         \
    F(tri_t) F(tri_instance) F(tri_triangle) F(rounds)
#define NB_LAYOUT_FIELDS_GpuNeuralParams(F)                                                                  \
    F(box.center)                                                                                            \
    F(box.depth_pad)                                                                                         \
    F(box.extent)                                                                                            \
    F(box.fixed_depth_eps)                                                                                   \
    F(lod_primary)                                                                                           \
    F(lod_secondary)                                                                                         \
    F(roughness) F(metallic) F(threshold) F(max_rounds) F(leaves_per_round) F(occupancy) F(materials)        \
        F(material_fits) F(material_spread) F(split_chunk) F(split_min_pairs) F(max_rounds_secondary)        \
            F(truncated_shadows_occlusion) F(leaves_per_round_camera) F(max_rounds_shadow) F(pad0) F(pad1) F(pad2)
#define NB_LAYOUT_FIELDS_GpuNeuralCounters(F)                                                                \
    F(pending_active)                                                                                        \
    F(queries_total)                                                                                         \
    F(leaf_cap_rays)                                                                                         \
    F(rounds)                                                                                                \
    F(queries_total_hi) F(overflow_first) F(pad1) F(pad2) F(queries_by_depth[0]) F(queries_by_depth[1])      \
        F(queries_by_depth[2]) F(queries_by_depth[3]) F(queries_by_depth[4]) F(queries_by_depth[5])          \
            F(queries_by_depth[6]) F(queries_by_depth[7]) F(queries_by_depth[8]) F(queries_by_depth[9])      \
                F(queries_by_depth[10]) F(queries_by_depth[11]) F(queries_by_depth[12])                      \
                    F(queries_by_depth[13]) F(queries_by_depth[14]) F(queries_by_depth[15])                  \
                        F(split_dispatch.x) F(split_dispatch.y) F(split_dispatch.z) F(overflow_dispatch.x)   \
                            F(overflow_dispatch.y) F(overflow_dispatch.z)
#define NB_LAYOUT_FIELDS_GpuNeuralAsset(F)                                                        \
    F(roots[0]) F(roots[1]) F(roots[2]) F(roots[3]) F(roots[4]) F(roots[5]) F(roots[6]) F(roots[7]) \
    F(material) F(metallic) F(roughness) F(backface_escape)

// --- distinct, exactly representable, non-zero values ------------------------------------------
// Field number k gets base value 16k (+1 for each further component), so every 4-byte word of a
// filled struct differs from every other (and from the zero the output buffer starts with).
NB_FN void nb_lv(NB_OUT(uint) x, uint k) { x = 16u * k + 1u; }
NB_FN void nb_lv(NB_OUT(int) x, uint k) { x = -int(16u * k + 1u); }
NB_FN void nb_lv(NB_OUT(float) x, uint k) { x = float(16u * k + 1u) + 0.5f; }
NB_FN void nb_lv(NB_OUT(vec2) x, uint k) { nb_lv(x.x, k); x.y = x.x + 1.0f; }
NB_FN void nb_lv(NB_OUT(vec3) x, uint k) { nb_lv(x.x, k); x.y = x.x + 1.0f; x.z = x.x + 2.0f; }
NB_FN void nb_lv(NB_OUT(vec4) x, uint k) { nb_lv(x.x, k); x.y = x.x + 1.0f; x.z = x.x + 2.0f; x.w = x.x + 3.0f; }
NB_FN void nb_lv(NB_OUT(uvec2) x, uint k) { nb_lv(x.x, k); x.y = x.x + 1u; }
NB_FN void nb_lv(NB_OUT(uvec3) x, uint k) { nb_lv(x.x, k); x.y = x.x + 1u; x.z = x.x + 2u; }
NB_FN void nb_lv(NB_OUT(uvec4) x, uint k) { nb_lv(x.x, k); x.y = x.x + 1u; x.z = x.x + 2u; x.w = x.x + 3u; }
NB_FN void nb_lv(NB_OUT(ivec2) x, uint k) { nb_lv(x.x, k); x.y = x.x - 1; }
NB_FN void nb_lv(NB_OUT(ivec3) x, uint k) { nb_lv(x.x, k); x.y = x.x - 1; x.z = x.x - 2; }
NB_FN void nb_lv(NB_OUT(ivec4) x, uint k) { nb_lv(x.x, k); x.y = x.x - 1; x.z = x.x - 2; x.w = x.x - 3; }

// nb_layout_fill_GpuFoo(s, seed): every field of s from the list; seed (the array element) shifts
// all values so that element 1 differs from element 0 (this checks the array stride = struct size).
#define NB_LV_FIELD(f) nb_lv(s.f, k); k += 1u;
#define NB_LAYOUT_FILL_FN(T, binding)                                                             \
    NB_FN void nb_layout_fill_##T(NB_OUT(T) s, uint seed) {                                       \
        uint k = 1u + seed * 4096u;                                                               \
        NB_LAYOUT_FIELDS_##T(NB_LV_FIELD)                                                         \
    }
NB_LAYOUT_STRUCTS(NB_LAYOUT_FILL_FN)

// Elements written per struct by layout.comp (one invocation each).
#define NB_LAYOUT_ELEMENTS 2u

#endif // NB_LAYOUT_FIELDS_H
