// The multi-resolution hash grid of N-BVH (paper §4, Müller et al. 2022), bit-compatible with
// tiny-cuda-nn's GridEncoding (notes tiny-cuda-nn §B, official notes §2) so that weights trained by
// the official implementation can be imported.
//
// Data layout (one grid shared by the 3 segment points):
//   entries of all levels are concatenated; level l owns entries [offset_l, offset_l + size_l);
//   each entry holds NB_GRID_FEATURES (4) contiguous values: feature f of entry e is at e*4 + f
//   (fp16 in the model file and on the GPU, fp32 master copy in the trainer).
// Level geometry (tcnn grid_scale / grid_resolution), computed ONCE on the CPU when a model is
// created (engine/neural/level_table.h) and stored in the model file as GpuHashLevel; shaders never
// recompute it with exp2/ceil:
//   scale_l = exp2f(l * log2f(per_level_scale)) * base_resolution - 1
//   res_l   = ceil(scale_l) + 1                       (vertices per axis)
//   size_l  = min(next_multiple(res_l^3, 8), 2^log2_hash_size)   (entries)
//   hashed  = size_l < res_l^3
// Lookup of a point x in [0,1]^3 (encoded, see neural_query.h) at level l, per axis:
//   pos = fma(scale_l, x, 0.5)  (the +0.5 staggers levels); cell = uint(int(floor(pos))) (wraps when
//   negative, as tcnn); frac = pos - floor(pos).  Corner c (bit 0 = x, bit 1 = y, bit 2 = z) is
//   cell + bit, weight = prod over axes of (bit ? frac : 1 - frac), corners accumulated 0..7.
//   index = (hashed ? (x*1 ^ y*2654435761 ^ z*805459861) : (x + y*res + z*res*res)) % size  in
//   wrapping uint32 arithmetic. tcnn does not clamp cell+1 == res: in dense levels that corner ALIASES
//   into the next row/slab ((res, y, z) reads the entry of (0, y+1, z)) and the last slab wraps via
//   % size. This is replicated on purpose (trained weights depend on it).
// GLSL has no pointers: these functions compute indices and weights; the caller fetches
// grid[(level.offset + index) * 4 + f] from whatever buffer it has.
#ifndef NB_HASHGRID_H
#define NB_HASHGRID_H
#include "compat.h"
#include "neural_config.h"

// CoherentPrime (tcnn default; Instant-NGP primes with pi_1 = 1 so x-neighbours stay coherent).
#define NB_HASH_PRIME_Y 2654435761u
#define NB_HASH_PRIME_Z 805459861u
// Limits of the level geometry a model file may hold (readers validate against these).
#define NB_GRID_MAX_LOG2_HASH 24u
#define NB_GRID_CORNERS 8u

// One level of the grid as stored in the model file and uploaded to the GPU (32 bytes, scalar layout).
struct GpuHashLevel {
    uint offset;     // first entry of the level in the concatenated table (entries, not values)
    uint size;       // entries of the level (the modulus of the index)
    uint resolution; // vertices per axis, res_l
    float scale;     // scale_l (float, exactly as tcnn computes it)
    uint hashed;     // 1: CoherentPrime hash, 0: dense x + y*res + z*res^2 (still % size)
    uint pad0;
    uint pad1;
    uint pad2;
};
NB_STATIC_ASSERT(sizeof(GpuHashLevel) == 32, "GpuHashLevel must be 32 bytes");

// The render passes read a level as one 16-byte word (lib/neural_grid.glsl nb_neural_level; the model
// upload packs it): offset, size, resolution with the hashed flag in bit 31 (make_level_table keeps
// resolutions below 2^31), scale. Not used by CUDA (the trainer reads GpuHashLevel).
#define NB_LEVEL_HASHED_BIT 0x80000000u
#if !defined(NB_CUDA)
NB_FN uvec4 nb_level_pack(GpuHashLevel l) {
    return uvec4(l.offset, l.size,
                 (l.resolution & ~NB_LEVEL_HASHED_BIT) | (l.hashed != 0u ? NB_LEVEL_HASHED_BIT : 0u),
                 floatBitsToUint(l.scale));
}
NB_FN GpuHashLevel nb_level_unpack(uvec4 w) {
    GpuHashLevel l;
    l.offset = w.x;
    l.size = w.y;
    l.resolution = w.z & ~NB_LEVEL_HASHED_BIT;
    l.scale = uintBitsToFloat(w.w);
    l.hashed = (w.z & NB_LEVEL_HASHED_BIT) != 0u ? 1u : 0u;
    l.pad0 = 0u;
    l.pad1 = 0u;
    l.pad2 = 0u;
    return l;
}
#endif

// Y-pair table (GPU only, engine/render/neural_grid_pack.h builds it when a model is uploaded; the model
// file does not change). In a dense level whose size is a power of two, the +y neighbour of the vertex
// at index i is at (i + res) % size, whatever the wrapping of the row-major index (size divides 2^32):
// the table's entry i of such a level holds the level's entries i and (i + res) % size, 16 bytes, so the
// corners c and c|2 of a cell come in one load. It covers the leading levels that qualify (levels are
// ordered coarse to fine: the dense ones first) and is indexed like the entries (level offset + index),
// from the 16-byte word given by the level buffer's extension word NB_LEVEL_YPAIR_WORD = (base,
// levels, 0, 0). Same words as the plain entries, so the same features to the bit.
#define NB_LEVEL_YPAIR_WORD NB_GRID_MAX_LEVELS
NB_FN bool nb_level_ypair_ok(GpuHashLevel l) { return l.hashed == 0u && l.size != 0u && (l.size & (l.size - 1u)) == 0u; }
// Index (within the level) of the +y neighbour of the vertex at index i of a qualifying level.
NB_FN uint nb_grid_ypair_partner(GpuHashLevel l, uint i) { return (i + l.resolution) & (l.size - 1u); }

// fma as tcnn's pos_fract uses it (fmaf). GLSL's fma is only guaranteed fused under `precise`;
// without it the result may differ by one float rounding, which moves a cell only when
// x*scale + 0.5 lands within 1 ulp of an integer.
#if defined(NB_GLSL)
#define nb_fmaf(a, b, c) fma((a), (b), (c))
#elif defined(NB_CUDA)
NB_FN float nb_fmaf(float a, float b, float c) { return fmaf(a, b, c); }
#else
NB_FN float nb_fmaf(float a, float b, float c) { return std::fma(a, b, c); }
#endif

// CoherentPrime hash of a grid vertex (wrapping uint32 multiplies), before the modulo.
NB_FN uint nb_hash_coherent_prime(uint x, uint y, uint z) {
    return x ^ (y * NB_HASH_PRIME_Y) ^ (z * NB_HASH_PRIME_Z);
}

// Index of grid vertex (x, y, z) inside its level, in [0, size). Dense levels use the row-major index
// (with tcnn's aliasing at x == res or y == res, see the header comment).
NB_FN uint nb_grid_vertex_index(GpuHashLevel level, uint x, uint y, uint z) {
    uint idx;
    if (level.hashed != 0u) {
        idx = nb_hash_coherent_prime(x, y, z);
    } else {
        idx = x + y * level.resolution + z * (level.resolution * level.resolution);
    }
#if defined(NB_GLSL)
    return idx % level.size;
#else
    // The same value as idx % size, without the integer division where size is a power of two (every
    // hashed level: size = 2^T). CUDA trainer, H200: grid backward 0.648 -> 0.607 ms, encode 0.182 ->
    // 0.196, step -2 %. The GLSL query kernels keep the modulo: the same branch there made the hybrid
    // frames 3-6 % slower (results/perf/dropped/README.md).
    uint size = level.size;
    return (size & (size - 1u)) == 0u ? (idx & (size - 1u)) : (idx % size);
#endif
}

// Continuous position of an encoded coordinate at a level (one axis): integer cell and fraction.
// The cell wraps to a large uint for negative positions exactly like tcnn's (uint32_t)(int)floorf.
// Callers keep x within [-1, 2] (neural_query.h clamps), so int(floor(pos)) never overflows.
NB_FN uint nb_grid_axis_position(float scale, float x, NB_OUT(float) frac) {
    float pos = nb_fmaf(scale, x, 0.5f);
    float fl = floor(pos);
    frac = pos - fl;
    return uint(int(fl));
}

// Cell and fractions of point p (encoded, ~[0,1]^3) at a level.
NB_FN void nb_grid_position(GpuHashLevel level, vec3 p, NB_OUT(uvec3) cell, NB_OUT(vec3) frac) {
    float fx, fy, fz;
    uint cx = nb_grid_axis_position(level.scale, p.x, fx);
    uint cy = nb_grid_axis_position(level.scale, p.y, fy);
    uint cz = nb_grid_axis_position(level.scale, p.z, fz);
    cell = uvec3(cx, cy, cz);
    frac = vec3(fx, fy, fz);
}

// Index (within the level) of corner c in 0..7 of a cell: bit 0 -> x+1, bit 1 -> y+1, bit 2 -> z+1.
NB_FN uint nb_grid_corner_index(GpuHashLevel level, uvec3 cell, uint corner) {
    return nb_grid_vertex_index(level, cell.x + (corner & 1u), cell.y + ((corner >> 1u) & 1u),
                                cell.z + ((corner >> 2u) & 1u));
}

// Entry in the concatenated table (multiply by NB_GRID_FEATURES and add f for the value index).
NB_FN uint nb_grid_corner_entry(GpuHashLevel level, uvec3 cell, uint corner) {
    return level.offset + nb_grid_corner_index(level, cell, corner);
}

// Trilinear weight of corner c, multiplied in tcnn's order (x, then y, then z).
NB_FN float nb_grid_corner_weight(vec3 frac, uint corner) {
    float w = 1.0f;
    w *= ((corner & 1u) != 0u) ? frac.x : (1.0f - frac.x);
    w *= (((corner >> 1u) & 1u) != 0u) ? frac.y : (1.0f - frac.y);
    w *= (((corner >> 2u) & 1u) != 0u) ? frac.z : (1.0f - frac.z);
    return w;
}

// Position of feature f of level l of segment point k in the 96-wide MLP input:
// points in ray order, then level-major, then feature (tcnn output order, RepeatedComposite concat).
NB_FN uint nb_feature_slot(uint point, uint level, uint feature) {
    return point * NB_POINT_FEATURES + level * NB_GRID_FEATURES + feature;
}

#endif // NB_HASHGRID_H
