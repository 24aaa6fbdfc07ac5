// GPU-side records of the neural ray queries (issue 4): the batched query kernels
// (passes/neural_eval_*.comp: a flat list of object-space queries, used by tests and the benchmark)
// and the renderer's neural pass (passes/neural_query_*.comp: the pending (ray, leaf) queue of
// wavefront_gpu.h). The network math itself lives in hashgrid.h, mlp.h and neural_query.h.
//
// Weight and grid buffers hold fp16 values PACKED TWO PER uint (low half = even element), so the scalar
// path needs neither shaderFloat16 nor 16-bit storage (unpackHalf2x16 is core GLSL); the
// cooperative-matrix path reads the same bytes as float16_t.
#ifndef NB_NEURAL_GPU_H
#define NB_NEURAL_GPU_H
#include "compat.h"
#include "intersect.h"
#include "neural_query.h"
#include "wavefront_gpu.h" // NB_STAT_DEPTHS

// Threads per workgroup of the query kernels. The cooperative-matrix kernel maps one subgroup of 32
// (checked on the host: it is only built on devices whose subgroup size is 32) to 32 queries.
#define NB_NEURAL_GROUP 64u
#define NB_NEURAL_COOP_SUBGROUP 32u

// One object-space query: the ray and its slab interval with the (dilated) leaf box. t_entry < 0 means
// the origin is inside the leaf (reversed query, neural_query.h).
struct GpuNeuralQuery {
    vec3 origin;
    float t_entry;
    vec3 dir;
    float t_exit;
};
NB_STATIC_ASSERT(sizeof(GpuNeuralQuery) == 32, "GpuNeuralQuery layout");

// Decoded result of one query.
#define NB_NEURAL_VISIBLE 1u   // y0 > threshold
#define NB_NEURAL_ACCEPTED 2u  // the depth decode accepted the hit (inside-origin margin)
struct GpuNeuralHit {
    vec3 normal;       // object space, unit length
    float t;           // forward-ray parameter of the hit (valid when both flags are set)
    vec3 albedo;       // y5..7 (linear base colour)
    float visibility;  // y0
    float depth;       // y1 (before the clamp of the decode)
    uint flags;        // NB_NEURAL_*
    uint pad0;
    uint pad1;
};
NB_STATIC_ASSERT(sizeof(GpuNeuralHit) == 48, "GpuNeuralHit layout");

// Push constants of the eval kernels (the encoding box of the one asset the queries belong to).
struct GpuNeuralEvalPush {
    GpuEncodingBox box;
    uint count;        // queries: the dispatch's valid indices are [first, count)
    float threshold;   // visibility threshold (NB_VISIBILITY_THRESHOLD by default)
    uint first;        // index of the dispatch's first query (a multiple of NB_NEURAL_GROUP)
    uint pad1;
};
NB_STATIC_ASSERT(sizeof(GpuNeuralEvalPush) == 48, "GpuNeuralEvalPush layout");

// Bindings of the eval kernels (set 0).
#define NB_NEVAL_BIND_LEVELS 0u   // uvec4[]: NB_GRID_MAX_LEVELS levels (nb_level_pack), then NB_LEVEL_YPAIR_WORD
#define NB_NEVAL_BIND_GRID 1u     // uint[]: fp16 pairs, entry e = words 2e, 2e+1 (features 0..3); then the y-pair table (hashgrid.h)
#define NB_NEVAL_BIND_MLP 2u      // uint[]: fp16 pairs, NB_MLP_WEIGHT_COUNT / 2 words (coopmat: transposed)
#define NB_NEVAL_BIND_QUERIES 3u  // GpuNeuralQuery[]
#define NB_NEVAL_BIND_HITS 4u     // GpuNeuralHit[]
#define NB_NEVAL_BIND_FEATURES 5u // uvec2[]: split kernels' features (nb_split_index)

// Leaf interval of a query (official notes §1): the slab interval of the ray with the leaf box dilated
// by NB_LEAF_DILATION of its extent about its centre (as the trainer's dilate_box), with
// tmin = -inf so an origin inside the leaf gives t_entry < 0. False when the line misses the box.
#define NB_LEAF_DILATION 1e-5f
NB_FN bool nb_neural_leaf_interval(vec3 org, vec3 inv_dir, vec3 lo, vec3 hi, NB_OUT(float) t_entry,
                                   NB_OUT(float) t_exit) {
    vec3 c = (lo + hi) * 0.5f;
    vec3 half_ext = (hi - lo) * (0.5f * (1.0f + NB_LEAF_DILATION));
    return nb_intersect_aabb_interval(org, inv_dir, c - half_ext, c + half_ext, -NB_INF, NB_INF, t_entry, t_exit);
}

// Bounds the renderer stores for the N-BVH's nodes (GpuBvhNode child boxes, engine/render/
// neural_model_gpu.cpp): the node box grown by twice the leaf dilation of its extent plus 1e-6 of its
// largest coordinate (and 1e-30), so that every leaf interval nb_neural_leaf_interval computes below a
// node (dilated about the leaf's centre, with float rounding) lies inside the node's box. Slab entry
// and exit distances are monotonic in the box bounds, so a subtree whose box a ray enters after t is
// entered by none of its leaves before t, and one it leaves before t is left by all of its leaves
// before t: the walk may cull by the round's worst kept leaf key and, resumed, by the ray's last queued
// key (lib/neural_traverse.glsl) without dropping a leaf (tests/neural/neural_cull_bounds_test.cpp).
NB_FN void nb_neural_cull_bounds(NB_INOUT(vec3) lo, NB_INOUT(vec3) hi) {
    vec3 m = max(abs(lo), abs(hi));
    float pad = max(1e-6f * max(m.x, max(m.y, m.z)), 1e-30f);
    vec3 grow = (hi - lo) * (2.0f * NB_LEAF_DILATION) + vec3(pad);
    lo = lo - grow;
    hi = hi + grow;
}

// fp16 <-> uint packing on the host matches unpackHalf2x16: element 2k in bits 0..15, 2k+1 in 16..31.

// ---- Renderer integration (wavefront loop, engine/render/neural_stage.h) ---------------------------
// The hit SOA's triangle word of a neural hit (shade.comp then reads the ray's GpuNeuralRayState).
#define NB_NEURAL_TRIANGLE 0xFFFFFFFEu

// Per path ray (one per slot of the queue being traced): the best neural hit so far and the ordering
// key of the last leaf queried. Leaves are visited in increasing key = (max(t_entry, tmin), instance,
// leaf): each round re-traverses the scene for the smallest key above the last one whose entry is still
// in front of the best hit (triangle or neural), so overlapping leaves of one or several instances are
// all queried in order and the closest accepted hit wins.
// Leaves a ray may queue per round (the next ones in key order in front of its best hit): one
// traversal and one query round serve several leaf visits; the pending queue holds that many pairs per ray.
#define NB_NL_MAX_LEAVES_PER_ROUND 4u
// Pass-constant bit of op 0 of passes/neural_traverse.comp and neural_shadow.comp: the rays in ray-sort
// order (shared/wavefront_gpu.h NB_RS_*, passes/ray_sort.comp); bits 0-1 are the op, bit 2 the half.
#define NB_NL_MODE_SORTED 8u
#define NB_NRAY_TRACE 0u    // needs a traversal round
#define NB_NRAY_PENDING 1u  // a (ray, leaf) pair is queued
#define NB_NRAY_DONE 2u
// A group is queued and is the ray's last: its traversal found fewer leaves than it looked for in
// front of the best hit (every leaf left in front was queued; hits only move the limit closer), or it
// spends the leaf budget (a leaf left is passed). The resumed round then finishes the ray without
// re-traversing.
#define NB_NRAY_PENDING_LAST 3u
// A shadow ray's group is queued that spends its leaf budget under --neural-truncated-shadows block or
// P > 0, and its traversal found one leaf more in front of the ray's end (looked for, never queued): its
// key's distance replaces key_t. The resumed round finishes the ray without re-traversing: occluded by
// that leaf (with probability P) when no hit of the group occludes it and the leaf lies in front of the
// ray's end.
#define NB_NRAY_PENDING_CAP 4u
struct GpuNeuralRayState {
    vec3 normal;    // world-space unit normal of the best neural hit
    float best_t;   // NB_INF: none
    uint albedo_rg; // albedo of the best hit, fp16 (GLSL packHalf2x16)
    uint albedo_b;  // ... blue, fp16 in the low half
    uint hit_leaf;  // N-BVH node (model order) that answered the best hit: its material (GpuNeuralParams.materials)
    uint instance;  // neural instance of the best hit
    float key_t;    // key of the last queued leaf
    uint key_instance;
    uint key_leaf;
    uint status;    // NB_NRAY_*
    float tri_t;    // closest triangle hit of round 0 (NB_INF: none)
    uint tri_instance;
    uint tri_triangle;
    uint rounds;    // leaves queried so far
};
NB_STATIC_ASSERT(sizeof(GpuNeuralRayState) == 64, "GpuNeuralRayState layout");
// The passes move a state as 4 16-byte words in field order (lib/neural_bindings.glsl nb_state_load,
// nb_state_store); the host reads the buffer as this struct (wavefront.cpp trace).

// One neural asset of the model (engine/neural/model_file.h ModelAsset), indexed by a neural
// GpuInstance's blas_root: where its N-BVH subtree starts in each LoD's GPU node array, and the scene
// material its hits are shaded with (the albedo is the network's).
#define NB_NEURAL_MAX_LODS 8u
struct GpuNeuralAsset {
    uint roots[NB_NEURAL_MAX_LODS]; // GPU node of its cut per LoD (LoDs past the model's: the coarsest)
    uint material;                  // index into the scene materials (emission, transmission)
    float metallic;                 // engine/neural/asset_table.h asset_shading: factor x mean texture
    float roughness;
    // 1: a ray leaving a hit of this asset seen from behind skips back-facing neural hits
    // (NB_RAY_BACKFACE_BIT, shared/wavefront_gpu.h; --neural-backface-escape); 0: off.
    uint backface_escape;
};
NB_STATIC_ASSERT(sizeof(GpuNeuralAsset) == 48, "GpuNeuralAsset layout");

// Neural constants of a render (storage buffer, one struct).
struct GpuNeuralParams {
    GpuEncodingBox box;
    uint lod_primary;     // N-BVH cut used by camera rays (--lod)
    uint lod_secondary;   // ... by rays after the first hit (--secondary-lod)
    float roughness;      // < 0: the asset's material; else an explicit override (--neural-roughness)
    float metallic;       // < 0: the asset's material; else --neural-metallic
    float threshold;      // visibility threshold
    uint max_rounds;      // leaves queried per ray at most (then the best hit so far is kept)
    // 1..NB_NL_MAX_LEAVES_PER_ROUND leaves queued per traversal round by rays after the first hit and
    // by shadow rays (--neural-leaves-per-round); camera rays: leaves_per_round_camera.
    uint leaves_per_round;
    // Occupancy masks (shared/neural_occupancy.h): their first word in the node-bounds buffer
    // (NB_BIND_NBVH_BOUNDS seen as words, after the NB_NBVH_BOUNDS_WORDS per node of the bounds), 0 =
    // none or off.
    uint occupancy;
    // Per-node materials (engine/neural/node_materials.h, nb_pack_node_material): their first word in
    // the same buffer, one word per node; 0 = none or off (hits take their asset's metallic/roughness).
    uint materials;
    // Per-node material fits (node_materials.h, nb_node_fit_eval): their first word in the same buffer,
    // NB_NODE_FIT_WORDS per node; 0 = none or off (then `materials`). --neural-materials mix|fit|node|asset.
    uint material_fits;
    // 1: a hit's metallic/roughness also takes the fit's spread (nb_node_fit_spread), --neural-materials mix.
    uint material_spread;
    // Pairs of a round the split query pass takes (its features buffer's capacity); the fused pass
    // takes the rest (NB_QUERY_MODE_OVERFLOW). 0: the fused pass takes every pair.
    uint split_chunk;
    // A round of fewer pairs than this goes to the fused pass whole (passes/neural_args.comp): its
    // dispatch fills the GPU about once, and the split pass's two dispatches then cost more than they
    // save (--neural-split-min-pairs). 0: every round starts with the split pass.
    uint split_min_pairs;
    // Leaves queried per ray at most by rays after the first hit (camera rays: max_rounds; shadow rays:
    // max_rounds_shadow); <= max_rounds (--neural-max-leaves-secondary).
    uint max_rounds_secondary;
    // The probability that a shadow ray truncated by its leaf budget is occluded, in [0, 1]
    // (--neural-truncated-shadows: block 1, pass 0; lib/neural_traverse.glsl nb_nl_shadow_blocked).
    float truncated_shadows_occlusion;
    // 1..NB_NL_MAX_LEAVES_PER_ROUND leaves queued per traversal round by camera rays
    // (--neural-leaves-per-round-camera). The pending queue holds the larger of the two per ray.
    uint leaves_per_round_camera;
    // Leaves queried per shadow ray at most, <= max_rounds (--neural-max-leaves-shadow; by default
    // max_rounds_secondary): shadow rays' truncation leaks or blocks light, path rays' changes paths.
    uint max_rounds_shadow;
    uint pad0;
    uint pad1;
    uint pad2;
};
NB_STATIC_ASSERT(sizeof(GpuNeuralParams) == 112, "GpuNeuralParams layout");

// A node's metallic and roughness in one word: unorm16 each, metallic in the low half (GLSL
// unpackUnorm2x16 reads it back as vec2(metallic, roughness)).
NB_FN uint nb_pack_node_material(float metallic, float roughness) {
    float m = metallic > 0.0f ? (metallic < 1.0f ? metallic : 1.0f) : 0.0f; // NaN -> 0
    float r = roughness > 0.0f ? (roughness < 1.0f ? roughness : 1.0f) : 0.0f;
    return uint(m * 65535.0f + 0.5f) | (uint(r * 65535.0f + 0.5f) << 16u);
}

// A node's metallic and roughness as linear functions of the hit's predicted albedo (node_materials.h):
// NB_NODE_FIT_WORDS words of two fp16 each (GLSL unpackHalf2x16: low half first), (m0, m_r), (m_g, m_b),
// (r0, r_r), (r_g, r_b): metallic = m0 + m_r r + m_g g + m_b b, roughness likewise, unclamped here;
// then (s_m, s_r): the spread of what the fit leaves (residual standard deviations; s_r negative when
// the residuals of metallic and roughness are anti-correlated). A hit takes fit + sign * spread with a
// random sign (a two-point mixture of the node's texels' materials: their mean and variance).
#define NB_NODE_FIT_WORDS 5u
NB_FN vec2 nb_node_fit_eval(vec2 m01, vec2 m23, vec2 r01, vec2 r23, vec3 albedo) {
    return vec2(m01.x + m01.y * albedo.x + m23.x * albedo.y + m23.y * albedo.z,
                r01.x + r01.y * albedo.x + r23.x * albedo.y + r23.y * albedo.z);
}
NB_FN vec2 nb_node_fit_spread(vec2 fit, vec2 spread, uint random_bits) {
    float s = (random_bits & 1u) != 0u ? 1.0f : -1.0f;
    return fit + s * spread;
}

// The split query pass (engine/render/neural_stage.h NeuralRenderOptions::split_query): a gather pass
// (passes/neural_gather.comp) writes each pair's 96 features as NB_SPLIT_FEATURE_QUADS fp16 quads to a
// features buffer (nb_split_index: blocks of NB_NEURAL_GROUP pairs, tile-major inside a block), then an MLP
// pass (passes/neural_query_mlp32.comp) reads them. The buffer holds split_chunk pairs (one binding);
// a round with more pairs than that (a pending half can hold more) gives the rest to the fused query
// pass, dispatched after them with NB_QUERY_MODE_OVERFLOW (its pairs start at
// GpuNeuralCounters::overflow_first: split_chunk, or 0 for a round of fewer than split_min_pairs pairs,
// which the fused pass takes whole).
#define NB_SPLIT_FEATURE_QUADS 24u // NB_SEGMENT_POINTS * NB_GRID_MAX_LEVELS, 8 bytes each
#define NB_QUERY_MODE_OVERFLOW 16u // pass-constant mode bit of the fused query pass (bits 0-3: neural_traverse.glsl)

// The features buffer: each workgroup's NB_NEURAL_GROUP pairs own one contiguous block (12 KiB, so a
// pair's features lie in one block; quad-major over the whole buffer put a pair's quads 174 MB apart in
// a 4 GB buffer), and inside it the 96 features are NB_SPLIT_TILES tiles of 16 (a point's 4 levels, 4
// quads), each a row-major NB_NEURAL_GROUP x 16 fp16 matrix (2 KiB): the MLP pass loads its first
// layer's A operands (16 pairs x 16 features, 512 contiguous bytes) straight from the buffer with
// cooperative-matrix loads, no staging in shared memory, and the gather pass stores a pair's tile row
// (32 bytes) at once, a subgroup's stores 1 KiB contiguous.
#define NB_SPLIT_TILES 6u        // NB_SPLIT_FEATURE_QUADS / 4
#define NB_SPLIT_TILE_ROW_WORDS 2u // 16-byte words per pair and tile (16 fp16 features)
// 16-byte word of pair k's row of tile t (its features 16t..16t+15; quads 4t..4t+3).
NB_FN uint nb_split_tile_word(uint k, uint t) {
    return (k / NB_NEURAL_GROUP) * (NB_NEURAL_GROUP * NB_SPLIT_FEATURE_QUADS / 2u) +
           t * (NB_NEURAL_GROUP * NB_SPLIT_TILE_ROW_WORDS) + (k % NB_NEURAL_GROUP) * NB_SPLIT_TILE_ROW_WORDS;
}
// Quad s (features 4s..4s+3) of the round's pair k (k < split_chunk) in the features buffer, in quads.
NB_FN uint nb_split_index(uint k, uint s) { return 2u * nb_split_tile_word(k, s / 4u) + (s & 3u); }

struct GpuNeuralCounters {
    uint pending_active;  // pairs the current neural_query dispatch processes
    uint queries_total;   // statistics: queries of the render (path and shadow rays), low 32 bits
    uint leaf_cap_rays;   // statistics: rays (path and shadow) that spent their leaf budget (the budget
                          // may have truncated them: a leaf left in front of their best hit)
    uint rounds;          // statistics: rounds with at least one pair
    // High 32 bits of queries_total: the one statistic that grows with the leaf budget (up to max_rounds
    // queries per ray), so that no wave size or --neural-max-leaves can wrap it within a submission (the
    // ray counters grow by at most 2 per path and bounce: wave_plan.h counter_safe_paths).
    uint queries_total_hi;
    // First pair of the round the fused pass takes after the split pass (NB_QUERY_MODE_OVERFLOW),
    // written by passes/neural_args.comp: split_chunk, or 0 (a round below split_min_pairs).
    uint overflow_first;
    uint pad1;
    uint pad2;
    // Statistics: queries per bounce of the path (index = depth, the last bucket also counting deeper
    // ones; as the ray counters of wavefront_gpu.h), 32-bit like the ray counters (read and
    // summed in 64 bits after every submission; a bounce's queries in one submission stay below 2^32:
    // wave_plan.h bounds the leaves queued per wave).
    uint queries_by_depth[NB_STAT_DEPTHS];
    // Split query pass (GpuNeuralParams::split_chunk > 0), written by passes/neural_args.comp: the
    // indirect dispatch of the round's first split_chunk pairs (gather and MLP pass alike; none for a
    // round below split_min_pairs), and of the rest through the fused pass.
    GpuDispatchArgs split_dispatch;
    GpuDispatchArgs overflow_dispatch;
};
NB_STATIC_ASSERT(sizeof(GpuNeuralCounters) == 32 + 4 * NB_STAT_DEPTHS + 24, "GpuNeuralCounters layout");
// Byte offsets of split_dispatch and overflow_dispatch (vkCmdDispatchIndirect).
#define NB_NEURAL_SPLIT_DISPATCH_OFFSET (32u + 4u * NB_STAT_DEPTHS)
#define NB_NEURAL_OVERFLOW_DISPATCH_OFFSET (NB_NEURAL_SPLIT_DISPATCH_OFFSET + 12u)

// 64-bit counter (lo, hi) += n in 32-bit words (one writer at a time: passes/neural_args.comp).
NB_FN void nb_add_u64(NB_INOUT(uint) lo, NB_INOUT(uint) hi, uint n) {
    uint sum = lo + n;
    if (sum < lo) hi += 1u;
    lo = sum;
}

// Bindings of the renderer's set 0 after shared/scene_gpu.h's NB_BINDING_COUNT (20).
#define NB_BIND_NEURAL_LEVELS 20u
#define NB_BIND_NEURAL_GRID 21u
#define NB_BIND_NEURAL_MLP 22u
#define NB_BIND_NBVH_NODES 23u
#define NB_BIND_NBVH_BOUNDS 24u
// Words per N-BVH node at the start of that buffer: lo xyz, 0, hi xyz, 0 (two 16-byte loads; packed as
// 6 words, the box took six 4-byte loads: the buffer is read per leaf a ray walks).
#define NB_NBVH_BOUNDS_WORDS 8u
#define NB_BIND_NEURAL_STATE 25u
#define NB_BIND_NEURAL_PARAMS 26u
#define NB_BIND_NEURAL_COUNTERS 27u
#define NB_BIND_NEURAL_MLP_T 28u    // the weights with each matrix transposed (cooperative-matrix pass)
#define NB_BIND_NEURAL_ASSETS 29u   // GpuNeuralAsset[]
#define NB_NEURAL_BINDING_END 32u    // 30, 31: NB_BIND_PENDING_LEAVES_1, NB_BIND_RAY_SORT (shared/scene_gpu.h)

#endif
