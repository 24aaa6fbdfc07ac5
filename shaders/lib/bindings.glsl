// Descriptor set 0 of every wavefront pass (binding indices: shared/scene_gpu.h), the scene feature
// specialization constants and the per-pass push constants. Included first by every pass.
#ifndef NB_BINDINGS_GLSL
#define NB_BINDINGS_GLSL
#extension GL_EXT_scalar_block_layout : require
#ifdef NB_TEXTURE_ARRAY
// Texture-array variants of the passes that sample textures (shaders/CMakeLists.txt, lib/textures.glsl).
#extension GL_EXT_nonuniform_qualifier : require
#endif

#include "shared/compat.h"
#include "shared/bvh_node.h"
#include "shared/wide_bvh_node.h"
#include "shared/scene_gpu.h"
#include "shared/wavefront_gpu.h"
#include "shared/sampling.h"

// Scene features (engine/render/feature_set.h). Disabled features are compiled out of the pipelines
// by the driver, so a scene without textures never fetches a texel.
layout(constant_id = NB_SC_TEXTURES) const bool NB_HAS_TEXTURES = false;
layout(constant_id = NB_SC_NORMAL_MAPS) const bool NB_HAS_NORMAL_MAPS = false;
layout(constant_id = NB_SC_EMISSION) const bool NB_HAS_EMISSION = false;
layout(constant_id = NB_SC_ENVIRONMENT) const bool NB_HAS_ENVIRONMENT = false;
layout(constant_id = NB_SC_ALPHA_MASK) const bool NB_HAS_ALPHA_MASK = false;
layout(constant_id = NB_SC_TRANSMISSION) const bool NB_HAS_TRANSMISSION = false;
layout(constant_id = NB_SC_NEURAL) const bool NB_HAS_NEURAL = false;
layout(constant_id = NB_SC_PUNCTUAL_LIGHTS) const bool NB_HAS_PUNCTUAL = false;
layout(constant_id = NB_SC_SINGLE_SIDED) const bool NB_HAS_SINGLE_SIDED = false;

layout(push_constant, scalar) uniform PassConstantsBlock { GpuPassConstants pc; };

layout(set = 0, binding = NB_BIND_PARAMS, scalar) readonly buffer ParamsBuffer { GpuFrameParams params; };
layout(set = 0, binding = NB_BIND_COUNTERS, scalar) coherent buffer CountersBuffer { GpuQueueCounters counters; };
layout(set = 0, binding = NB_BIND_TLAS_NODES, std430) readonly buffer TlasBuffer { GpuBvhNode tlas_nodes[]; };
layout(set = 0, binding = NB_BIND_BLAS_NODES, std430) readonly buffer BlasBuffer { GpuWideNode blas_nodes[]; };
layout(set = 0, binding = NB_BIND_INSTANCES, std430) readonly buffer InstanceBuffer { GpuInstance instances[]; };
layout(set = 0, binding = NB_BIND_TRIANGLES, std430) readonly buffer TriangleBuffer { GpuTriangle triangles[]; };
layout(set = 0, binding = NB_BIND_VERTICES, scalar) readonly buffer VertexBuffer { GpuVertex vertices[]; };
layout(set = 0, binding = NB_BIND_MATERIALS, scalar) readonly buffer MaterialBuffer { GpuMaterial materials[]; };
layout(set = 0, binding = NB_BIND_TEXTURE_INFOS, scalar) readonly buffer TextureInfoBuffer { GpuTextureInfo texture_infos[]; };
// Binding NB_BIND_TEXELS (the texels, or the texture-array images) is declared by lib/textures.glsl, so only
// the passes that sample textures declare it (and have a texture-array variant, shaders/CMakeLists.txt).
layout(set = 0, binding = NB_BIND_LIGHTS, scalar) readonly buffer LightBuffer { GpuLight lights[]; };
layout(set = 0, binding = NB_BIND_LIGHT_CDF, scalar) readonly buffer LightCdfBuffer { float light_cdf[]; };
// Environment: rgba texels (width*height*4, a unused: one 16-byte load per texel), then the marginal row
// cdf (height+1), then one conditional cdf per row (height*(width+1)), then the texels' densities
// (width*height); layout written by engine/render/environment_sampler.cpp. Floats are read through
// nb_env_float (lib/env.glsl).
layout(set = 0, binding = NB_BIND_ENV, std430) readonly buffer EnvBuffer { vec4 env_data[]; };
layout(set = 0, binding = NB_BIND_RAYS, scalar) buffer RayBuffer { uint ray_words[]; };
layout(set = 0, binding = NB_BIND_HITS, scalar) buffer HitBuffer { uint hit_words[]; };
layout(set = 0, binding = NB_BIND_SHADOW_RAYS, scalar) buffer ShadowBuffer { uint shadow_words[]; };
// Radiance of the current sample of each pixel of the wave (index = pixel - pc.pixel_offset).
layout(set = 0, binding = NB_BIND_SAMPLE_RADIANCE, scalar) buffer SampleRadianceBuffer { vec3 sample_radiance[]; };
// Running sum over samples, per image pixel (rgb sum, a = samples accumulated).
layout(set = 0, binding = NB_BIND_FILM, scalar) buffer FilmBuffer { vec4 film[]; };
// The pending (ray, leaf) queue's two halves, one binding each (each may need most of one buffer's
// range: a 32M-path hybrid wave holds 2 x 2 x 48 bytes of pairs per path); slots address both, half 1
// from its half size on (lib/neural_bindings.glsl nb_nl_pending_index). A pair (GpuPendingLeaf) is 3
// consecutive 16-byte words here, read and written by lib/neural_bindings.glsl nb_pending_*.
layout(set = 0, binding = NB_BIND_PENDING_LEAVES, std430) buffer PendingLeafBuffer { uvec4 pending_leaves[]; };
layout(set = 0, binding = NB_BIND_PENDING_LEAVES_1, std430) buffer PendingLeafBuffer1 { uvec4 pending_leaves_1[]; };
#ifdef NB_SPLIT_FEATURES
#ifndef NB_SPLIT_FEATURES_ACCESS
#define NB_SPLIT_FEATURES_ACCESS readonly // the MLP pass; the gather pass writes
#endif
// The split query's passes (shared/neural_gpu.h NB_SPLIT_*) never touch the output image: their
// descriptor sets bind the features buffer here instead (the layout has no binding to spare: lavapipe
// allows 32 storage buffers per stage, and the split passes run only where cooperative matrices do).
// Seen as quads (nb_split_index) and as 16-byte words (nb_split_tile_word: the tile rows).
layout(set = 0, binding = NB_BIND_OUTPUT, std430) NB_SPLIT_FEATURES_ACCESS buffer SplitFeaturesBuffer { uvec2 split_features[]; };
layout(set = 0, binding = NB_BIND_OUTPUT, std430) NB_SPLIT_FEATURES_ACCESS buffer SplitFeatureTiles { uvec4 split_feature_tiles[]; };
#else
layout(set = 0, binding = NB_BIND_OUTPUT, scalar) buffer OutputBuffer { vec4 output_pixels[]; };
#endif
// Ray order of the traversal and shadow passes (shared/wavefront_gpu.h NB_RS_*).
layout(set = 0, binding = NB_BIND_RAY_SORT, std430) buffer RaySortBuffer {
    uint rs_bins[NB_RS_HEADER_WORDS];
    uint rs_order[];
};
// The same buffer in 16-byte units (queue_args.comp scans and zeroes the bins 4 at a time).
layout(set = 0, binding = NB_BIND_RAY_SORT, std430) buffer RaySortBins4 { uvec4 rs_bins4[]; };

// ---- SOA accessors (layout: shared/wavefront_gpu.h) ----------------------------------------------
uint ray_capacity() { return params.wave_capacity; }

vec3 ray_load3(uint queue, uint field, uint i) {
    uint w = nb_ray_word(queue, field, ray_capacity(), i, 3u);
    return vec3(uintBitsToFloat(ray_words[w]), uintBitsToFloat(ray_words[w + 1u]), uintBitsToFloat(ray_words[w + 2u]));
}
void ray_store3(uint queue, uint field, uint i, vec3 v) {
    uint w = nb_ray_word(queue, field, ray_capacity(), i, 3u);
    ray_words[w] = floatBitsToUint(v.x);
    ray_words[w + 1u] = floatBitsToUint(v.y);
    ray_words[w + 2u] = floatBitsToUint(v.z);
}
uint ray_load1(uint queue, uint field, uint i) { return ray_words[nb_ray_word(queue, field, ray_capacity(), i, 1u)]; }
void ray_store1(uint queue, uint field, uint i, uint v) { ray_words[nb_ray_word(queue, field, ray_capacity(), i, 1u)] = v; }

uint hit_load1(uint field, uint i) { return hit_words[nb_hit_word(field, ray_capacity(), i, 1u)]; }
void hit_store1(uint field, uint i, uint v) { hit_words[nb_hit_word(field, ray_capacity(), i, 1u)] = v; }
vec2 hit_load_bary(uint i) {
    uint w = nb_hit_word(NB_HIT_BARY, ray_capacity(), i, 2u);
    return vec2(uintBitsToFloat(hit_words[w]), uintBitsToFloat(hit_words[w + 1u]));
}
void hit_store_bary(uint i, vec2 b) {
    uint w = nb_hit_word(NB_HIT_BARY, ray_capacity(), i, 2u);
    hit_words[w] = floatBitsToUint(b.x);
    hit_words[w + 1u] = floatBitsToUint(b.y);
}

vec3 shadow_load3(uint field, uint i) {
    uint w = nb_shadow_word(field, ray_capacity(), i, 3u);
    return vec3(uintBitsToFloat(shadow_words[w]), uintBitsToFloat(shadow_words[w + 1u]), uintBitsToFloat(shadow_words[w + 2u]));
}
void shadow_store3(uint field, uint i, vec3 v) {
    uint w = nb_shadow_word(field, ray_capacity(), i, 3u);
    shadow_words[w] = floatBitsToUint(v.x);
    shadow_words[w + 1u] = floatBitsToUint(v.y);
    shadow_words[w + 2u] = floatBitsToUint(v.z);
}
uint shadow_load1(uint field, uint i) { return shadow_words[nb_shadow_word(field, ray_capacity(), i, 1u)]; }
void shadow_store1(uint field, uint i, uint v) { shadow_words[nb_shadow_word(field, ray_capacity(), i, 1u)] = v; }
// Hybrid renders: neural_shadow's decision "occluded" is a negative NB_SHADOW_TMAX (a shadow ray's own
// tmax is positive), read by shadow.comp together with the rest of the ray.
void nb_shadow_mark_occluded(uint i) { shadow_store1(NB_SHADOW_TMAX, i, floatBitsToUint(-1.0f)); }
bool nb_shadow_is_marked_occluded(float tmax) { return tmax < 0.0f; }

// Random bits of a ray's stochastic alpha coverage (shared/scene_gpu.h nb_alpha_covers): a path ray's
// are its NB_RAY_RNG word; a shadow ray's come from its path's slot in the wave (pixel, sample, depth).
uint nb_shadow_alpha_seed(uint slot) {
    uint pixel = nb_slot_pixel(slot, pc.pixel_offset, pc.wave_samples);
    return nb_pcg_hash(pixel ^ (pc.depth << 24u) ^ nb_slot_sample(slot, pc.sample_index, pc.wave_samples));
}

// Ray-sort bin of a ray (shared/wavefront_gpu.h nb_rs_key) in the scene's bounds (the sort header).
uint nb_rs_bin(vec3 o, vec3 d) {
    vec3 lo = vec3(uintBitsToFloat(rs_bins[NB_RS_BOUNDS]), uintBitsToFloat(rs_bins[NB_RS_BOUNDS + 1u]),
                   uintBitsToFloat(rs_bins[NB_RS_BOUNDS + 2u]));
    vec3 hi = vec3(uintBitsToFloat(rs_bins[NB_RS_BOUNDS + 3u]), uintBitsToFloat(rs_bins[NB_RS_BOUNDS + 4u]),
                   uintBitsToFloat(rs_bins[NB_RS_BOUNDS + 5u]));
    return nb_rs_key(o, d, lo, hi);
}
uint queue_count(uint queue) { return queue == 0u ? counters.ray_count0 : counters.ray_count1; }

// Affine transforms stored as three rows.
vec3 nb_xform_point(vec4 rows[3], vec3 p) {
    return vec3(dot(rows[0].xyz, p) + rows[0].w, dot(rows[1].xyz, p) + rows[1].w, dot(rows[2].xyz, p) + rows[2].w);
}
vec3 nb_xform_vector(vec4 rows[3], vec3 v) { return vec3(dot(rows[0].xyz, v), dot(rows[1].xyz, v), dot(rows[2].xyz, v)); }
// Normals transform with the inverse transpose: n_world = transpose(M^-1) n = columns of world_to_object.
vec3 nb_xform_normal(vec4 w2o[3], vec3 n) { return w2o[0].xyz * n.x + w2o[1].xyz * n.y + w2o[2].xyz * n.z; }

#endif
