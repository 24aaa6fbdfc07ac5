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
#include "neural_query.h"
#include "intersect.h"

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
    uint count;        // queries
    float threshold;   // visibility threshold (NB_VISIBILITY_THRESHOLD by default)
    uint pad0;
    uint pad1;
};
NB_STATIC_ASSERT(sizeof(GpuNeuralEvalPush) == 48, "GpuNeuralEvalPush layout");

// Bindings of the eval kernels (set 0).
#define NB_NEVAL_BIND_LEVELS 0u   // GpuHashLevel[NB_GRID_MAX_LEVELS]
#define NB_NEVAL_BIND_GRID 1u     // uint[]: fp16 pairs, entry e = words 2e, 2e+1 (features 0..3)
#define NB_NEVAL_BIND_MLP 2u      // uint[]: fp16 pairs, NB_MLP_WEIGHT_COUNT / 2 words
#define NB_NEVAL_BIND_QUERIES 3u  // GpuNeuralQuery[]
#define NB_NEVAL_BIND_HITS 4u     // GpuNeuralHit[]

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

// fp16 <-> uint packing on the host matches unpackHalf2x16: element 2k in bits 0..15, 2k+1 in 16..31.

#endif
