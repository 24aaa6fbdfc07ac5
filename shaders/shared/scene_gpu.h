// The scene as the wavefront renderer's shaders see it: instances, triangles, vertices, materials,
// textures, emissive-triangle lights and the environment. Written by engine/render/gpu_scene.cpp,
// read by shaders/passes/*.comp. Every buffer uses scalar block layout (vec3 = 12 bytes).
//
// Spaces: vertex positions/normals are in object space; an instance maps object -> world with an
// affine 3x4 matrix stored as three rows. Lights are pre-transformed to world space.
#ifndef NB_SCENE_GPU_H
#define NB_SCENE_GPU_H
#include "compat.h"

// ---- Instances (TLAS leaves) -------------------------------------------------------------------
// What a TLAS leaf item contains. Traversal only hands the item to the leaf handler of its kind;
// the triangle handler traverses a BLAS, the neural handler (later issue) queues (ray, leaf) pairs.
#define NB_INSTANCE_TRIANGLES 0u
#define NB_INSTANCE_NEURAL 1u
// Triangles seen by camera rays only: an inverted-hull outline shell (engine/scene/outline_shells.h),
// which rasterizing viewers draw at silhouettes and which must not shadow or hide what it encloses.
#define NB_INSTANCE_CAMERA_ONLY 2u

struct GpuInstance {
    vec4 object_to_world[3]; // rows of the affine 3x4 matrix
    vec4 world_to_object[3]; // rows of its inverse
    uint blas_root;          // index of the BLAS root in the shared BLAS node array
    uint first_triangle;     // offset of this mesh's triangles (BLAS leaf order) in the triangle array
    uint kind;               // NB_INSTANCE_*
    uint mesh;               // index of the CPU mesh (debug, stats)
};
NB_STATIC_ASSERT(sizeof(GpuInstance) == 112, "GpuInstance layout");

// A triangle: three indices into the global vertex array (mesh offset already added) and its material.
struct GpuTriangle {
    uint v0, v1, v2;
    uint material;
};
NB_STATIC_ASSERT(sizeof(GpuTriangle) == 16, "GpuTriangle layout");

// Object-space vertex. uv1 is only read when a texture reference asks for uv set 1.
struct GpuVertex {
    vec3 position; float u0;
    vec3 normal;   float v0;
    vec4 tangent;  // xyz tangent, w handedness (zero when the mesh has no tangents)
    vec2 uv1;
};
NB_STATIC_ASSERT(sizeof(GpuVertex) == 56, "GpuVertex layout");

// ---- Materials and textures ---------------------------------------------------------------------
// A texture reference: uv' = (dot(row0, (uv,1)), dot(row1, (uv,1))) (KHR_texture_transform).
struct GpuTexRef {
    int texture; // index into the texture table, -1 = none
    uint uv_set; // 0 or 1
    vec3 row0;
    vec3 row1;
};
NB_STATIC_ASSERT(sizeof(GpuTexRef) == 32, "GpuTexRef layout");

#define NB_ALPHA_OPAQUE 0u
#define NB_ALPHA_MASK 1u
#define NB_ALPHA_BLEND 2u

// Whether a surface of alpha `alpha` (factor x texture) stops a ray, by its glTF alphaMode: MASK where
// alpha >= cutoff; BLEND with probability alpha (the draw: the high 24 bits of `hash`), which keeps
// the estimator unbiased without sorting hits; OPAQUE always. One rule for the classical traversal
// (lib/traverse.glsl), both trainers' ground truth (trainer/ground_truth.cpp, cuda/sampling_kernels.cu)
// and the neural query of blended assets (lib/neural_query_pass.glsl, alpha = the learned visibility).
NB_FN bool nb_alpha_covers(uint mode, float alpha, float cutoff, uint hash) {
    if (mode == NB_ALPHA_MASK) return alpha >= cutoff;
    if (mode == NB_ALPHA_BLEND) return float(hash >> 8u) * (1.0f / 16777216.0f) < alpha;
    return true;
}

// glTF tangent-space normal mapping of the unit vertex normal n: t4 the interpolated tangent (xyz; w
// the handedness), texel the normal texture's rgb in [0,1], scale the material's normalTexture.scale.
// The tangent is made orthogonal to n (Gram-Schmidt), b = cross(n, t) * sign(w), and the result is
// tn.x t + tn.y b + tn.z n normalised (tn = 2 texel - 1, xy scaled). n itself where the tangent or
// the result degenerates (no tangents: zero). Both trainers' ground truth (trainer/ground_truth.cpp,
// trainer/cuda/sampling_kernels.cu); the classical shade pass (lib/material.glsl) maps in world space
// and falls back to an arbitrary frame without tangents, as the official implementation does.
NB_FN vec3 nb_normal_map(vec3 n, vec4 t4, vec3 texel, float scale) {
    vec3 t = vec3(t4.x, t4.y, t4.z);
    t = t - n * dot(n, t);
    float tl = length(t);
    if (!(tl > 1.0e-12f) || !(tl < 3.0e38f)) return n;
    t = t / tl;
    vec3 b = cross(n, t) * (t4.w < 0.0f ? -1.0f : 1.0f);
    vec3 m = t * ((texel.x * 2.0f - 1.0f) * scale) + b * ((texel.y * 2.0f - 1.0f) * scale) + n * (texel.z * 2.0f - 1.0f);
    float ml = length(m);
    return (ml > 1.0e-12f && ml < 3.0e38f) ? m / ml : n;
}

// glTF metallic-roughness material (+ transmission). Emissive already includes emissive_strength.
struct GpuMaterial {
    vec4 base_color;      // linear RGBA factor
    vec3 emissive;        // linear RGB factor (W/(m^2 sr) in scene units)
    float metallic;
    float roughness;
    float normal_scale;
    float alpha_cutoff;
    float transmission;
    uint alpha_mode;      // NB_ALPHA_*
    uint double_sided;    // 0: back faces are culled for every ray (lib/traverse.glsl)
    uint pad0, pad1;
    GpuTexRef base_color_tex;          // sRGB
    GpuTexRef metallic_roughness_tex;  // linear: G roughness, B metallic
    GpuTexRef normal_tex;              // linear tangent-space normal
    GpuTexRef emissive_tex;            // sRGB
};
NB_STATIC_ASSERT(sizeof(GpuMaterial) == 192, "GpuMaterial layout");

// All textures live in one buffer of RGBA8 texels (packed little-endian into a uint: R in the low byte),
// filtered bilinearly with repeat wrapping in the shader. One buffer instead of an image array keeps the
// descriptor layout fixed and needs no descriptor indexing.
struct GpuTextureInfo {
    uint offset; // first texel in the texel buffer
    uint width;
    uint height;
    uint pad;
};
NB_STATIC_ASSERT(sizeof(GpuTextureInfo) == 16, "GpuTextureInfo layout");

// ---- Lights -------------------------------------------------------------------------------------
// One array of lights: the emissive triangles [0, GpuFrameParams::light_count), then the
// KHR_lights_punctual lights [light_count, light_count + punctual_count).
//
// An emissive triangle (kind NB_LIGHT_TRIANGLE) in world space. Selection is proportional to power =
// luminance(emissive factor) * area, so the area-measure light pdf of a point is luminance(emissive) /
// total_power: the shader can evaluate it on a BSDF hit without a triangle -> light lookup (needed for MIS).
// A single-sided material emits only from its front face, the face rays can hit (back faces are culled):
// `side` is +1 (front = +cross(p1 - p0, p2 - p0)), -1 (mirroring instance: front = -cross) or 0 (double-sided).
//
// A punctual light (NB_LIGHT_POINT / SPOT / DIRECTIONAL) reuses the vertex fields: p0 = position (world),
// p1 = unit direction the light shines along (world), p2 = colour x intensity (cd; directional: lux), area =
// range (m, 0 = infinite). Spot cone (KHR_lights_punctual): attenuation = clamp(cos * spot_scale +
// spot_offset, 0, 1)^2 with cos = dot(p1, -wi); point lights have scale 0, offset 1.
#define NB_LIGHT_TRIANGLE 0u
#define NB_LIGHT_POINT 1u
#define NB_LIGHT_SPOT 2u
#define NB_LIGHT_DIRECTIONAL 3u

struct GpuLight {
    vec3 p0; uint instance;
    vec3 p1; uint triangle; // global triangle index (for material and uv lookups)
    vec3 p2; float area;    // world-space area (m^2)
    uint kind;              // NB_LIGHT_*
    float side;             // triangles: which faces emit (see above)
    float spot_scale;       // punctual: cone attenuation (see above)
    float spot_offset;
};
NB_STATIC_ASSERT(sizeof(GpuLight) == 64, "GpuLight layout");

// ---- Per-render parameters ----------------------------------------------------------------------
// One struct in a storage buffer (too big for push constants).
struct GpuFrameParams {
    // camera: pinhole, world space
    vec3 cam_eye;     float cam_tan_half_fov; // tan(yfov/2)
    vec3 cam_forward; float aspect;           // width / height
    vec3 cam_right;   uint width;
    vec3 cam_up;      uint height;
    // environment: equirectangular map rotated by env_rotation (radians) about +y; u = atan2(d.x,-d.z)/2pi
    // + 0.5, v = acos(d.y)/pi (official implementation §8). A constant environment is a 1x1 map.
    uint env_width;  uint env_height;
    float env_intensity; float env_rotation;
    float env_inv_mean; // 1 / mean(filtered luminance * sin(theta)); 0: a black map (no strategy)
    // emissive-triangle lights
    uint light_count;      // emissive triangles (0 when they have no power)
    float light_total_power; // sum of luminance(emissive) * area
    // path tracing
    uint max_depth;        // path segments (1 = direct light only)
    uint rr_start_depth;   // Russian roulette from this segment on
    uint seed;
    uint spp;
    uint wave_capacity;    // rays per queue (pixels processed per wave)
    float ray_epsilon;     // origin offset along the geometric normal, scaled by the scene size (m)
    uint instance_count;
    uint punctual_count;   // KHR_lights_punctual lights after the emissive triangles in the light array;
                           // their power cdf follows the emissive one in light_cdf (at light_count + 1)
    uint sort_rays;        // 1: shade.comp counts the rays it appends into the ray-sort bins (NB_RS_*)
    uint path_sampler;     // NB_SAMPLER_*: the path's random numbers (lib/path_sampler.glsl)
    uint pad0;
    uint pad1;
    uint pad2;
};
NB_STATIC_ASSERT(sizeof(GpuFrameParams) == 144, "GpuFrameParams layout");
#define NB_SAMPLER_RANDOM 0u // independent PCG numbers per path
#define NB_SAMPLER_SOBOL 1u  // Owen-scrambled Sobol pairs per pixel (shared/sampling.h nb_qmc_2d)

// ---- Descriptor set 0 bindings (one layout shared by every pass) --------------------------------
#define NB_BIND_PARAMS 0u
#define NB_BIND_COUNTERS 1u
#define NB_BIND_TLAS_NODES 2u
#define NB_BIND_BLAS_NODES 3u
#define NB_BIND_INSTANCES 4u
#define NB_BIND_TRIANGLES 5u
#define NB_BIND_VERTICES 6u
#define NB_BIND_MATERIALS 7u
#define NB_BIND_TEXTURE_INFOS 8u
#define NB_BIND_TEXELS 9u
#define NB_BIND_LIGHTS 10u
#define NB_BIND_LIGHT_CDF 11u
#define NB_BIND_ENV 12u
#define NB_BIND_RAYS 13u
#define NB_BIND_HITS 14u
#define NB_BIND_SHADOW_RAYS 15u
#define NB_BIND_SAMPLE_RADIANCE 16u
#define NB_BIND_FILM 17u
#define NB_BIND_PENDING_LEAVES 18u
#define NB_BIND_PENDING_LEAVES_1 30u // its half 1 (after the neural bindings 20-29 of shared/neural_gpu.h)
#define NB_BIND_RAY_SORT 31u         // ray order of the traversal and shadow passes (shared/wavefront_gpu.h NB_RS_*)
#define NB_BIND_OUTPUT 19u
#define NB_BINDING_COUNT 20u

// ---- Specialization constants: the scene's feature set (engine/render/feature_set.h) -------------
#define NB_SC_TEXTURES 0u
#define NB_SC_NORMAL_MAPS 1u
#define NB_SC_EMISSION 2u
#define NB_SC_ENVIRONMENT 3u
#define NB_SC_ALPHA_MASK 4u
#define NB_SC_TRANSMISSION 5u
#define NB_SC_NEURAL 6u
#define NB_SC_PUNCTUAL_LIGHTS 7u
#define NB_SC_SINGLE_SIDED 8u
#define NB_SC_COUNT 9u

#endif
