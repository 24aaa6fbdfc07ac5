// Training-ray generation with the first-leaf search over the current N-BVH cut (paper §3, §3.3;
// mirrors trainer/training_rays.cpp and cpu_backend.cpp draw_training_sample), and the ground truth
// of each sample by a closest-hit traversal of the asset's triangle BVH in the renderer's 4-wide layout
// with the shared ray/box and ray/triangle tests (shaders/shared/intersect.h).
// Compiled with --fmad=false (CMakeLists.txt) so the ray set matches the CPU backend's for a seed.
#include "shaders/shared/scene_gpu.h"
#include "shaders/shared/wide_bvh_node.h"
#include "trainer/cuda/clip_box.cuh"
#include "trainer/cuda/device_common.cuh"

namespace nbvh::cuda {
namespace {

struct Found { int32_t leaf; float t_entry, t_exit; };

// A node of a cut tree through the read-only cache: box (centre, half extent) and children (cut_tree.h).
struct LoadedNode {
    float centre[3], half[3];
    uint32_t left, right;
};
__device__ inline LoadedNode load_node(const CutNode* nodes, uint32_t i) {
    const float4 a = __ldg(reinterpret_cast<const float4*>(nodes + i));
    const uint4 b = __ldg(reinterpret_cast<const uint4*>(nodes + i) + 1);
    return LoadedNode{{a.x, a.y, a.z}, {a.w, __uint_as_float(b.x), __uint_as_float(b.y)}, b.z, b.w};
}

// A cut node's dilated box clipped: clip_regular where the ray allows it (every box of the tree is
// regular, cut_tree.h), else the general clip_dilated. The walk finds the same leaf, entry and exit
// either way (clip_box.cuh).
template <bool kRegularRay>
__device__ inline bool clip_node(const LoadedNode& n, vec3 o, vec3 d, const InvDir& id, const SlabRay& sr,
                                 float dilation, float& t0, float& t1) {
    if constexpr (kRegularRay)
        return clip_regular(n.centre, n.half, sr, t0, t1);
    else
        return clip_dilated(n.centre, n.half, o, d, id, dilation, t0, t1);
}

// first_leaf_of_cut (trainer/training_rays.cpp): nearest-first descent from a part's root, stopping at
// cut leaves, on the cut's compact tree. Same nodes in the same order as the CPU's walk of the base BVH.
template <bool kRegularRay>
__device__ Found first_leaf(const CutNode* nodes, uint32_t root, vec3 o, vec3 d, float dilation,
                            float min_exit) {
    Found best{-1, 0.0f, 0.0f};
    if (root == kCutNone) return best; // empty base BVH, or a root box no ray crosses
    const InvDir id = inv_dir(d);
    const SlabRay sr = slab_ray(o, d, id, dilation);
    float best_entry = NB_INF;
    // The nearer child goes on in registers (`node`, `te`), only the farther one is pushed: the same
    // visiting order as pushing both, with half the stack's local-memory traffic.
    uint32_t st_node[NB_BVH_MAX_DEPTH * 2 + 2];
    float st_t[NB_BVH_MAX_DEPTH * 2 + 2];
    int top = 0;
    float t0, t1;
    LoadedNode n = load_node(nodes, root);
    if (!clip_node<kRegularRay>(n, o, d, id, sr, dilation, t0, t1) || t1 <= min_exit) return best;
    uint32_t node = root;
    float te = t0;
    for (;;) {
        if (te < best_entry) {
            n = load_node(nodes, node);
            if (n.right == kCutLeafTag) {
                float ea = 0.0f, eb = 0.0f;
                clip_node<kRegularRay>(n, o, d, id, sr, dilation, ea, eb);
                best = Found{int32_t(n.left), ea, eb};
                best_entry = te;
            } else if (n.left != kCutNone || n.right != kCutNone) { // else a base leaf below no cut leaf
                uint32_t kn[2];
                float kt[2];
                int count = 0;
                const uint32_t kids[2] = {n.left, n.right};
                for (int k = 0; k < 2; ++k) {
                    const uint32_t child = kids[k];
                    if (child == kCutNone) continue;
                    const LoadedNode c = load_node(nodes, child);
                    if (clip_node<kRegularRay>(c, o, d, id, sr, dilation, t0, t1) && t1 > min_exit &&
                        t0 < best_entry) {
                        kn[count] = child;
                        kt[count++] = t0;
                    }
                }
                if (count == 2) { // the nearer (the right one on ties, as pushed last) goes on
                    const int near = kt[0] < kt[1] ? 0 : 1;
                    if (top + 1 > int(NB_BVH_MAX_DEPTH * 2 + 2)) return best; // cannot happen for a valid BVH
                    st_node[top] = kn[1 - near];
                    st_t[top++] = kt[1 - near];
                    node = kn[near];
                    te = kt[near];
                    continue;
                }
                if (count == 1) {
                    node = kn[0];
                    te = kt[0];
                    continue;
                }
            }
        }
        if (top == 0) break;
        --top;
        node = st_node[top];
        te = st_t[top];
    }
    return best;
}

// One attempt of a slot: the body of the CPU loop (cpu_backend.cpp draw_training_sample), on the
// attempt's own stream (trainer/pcg32.h SampleSlot).
struct Attempt {
    Found f;
    uint32_t cut;
    bool kept;
    vec3 o, d;
};

__device__ Attempt try_attempt(const DevAsset& a, const DevCuts& c, const SampleSlot& where, uint32_t attempt) {
    Pcg32 rng = where.attempt_rng(attempt);
    Attempt r;
    r.cut = c.count > 1 ? min(uint32_t(rng.next_float() * float(c.count)), c.count - 1u) : 0u;
    // The part (trainer/training_asset.h pick_part; drawn only when there are several).
    const uint32_t pi = a.parts > 1 ? min(uint32_t(rng.next_float() * float(a.parts)), a.parts - 1u) : 0u;
    const float* pb = a.part_boxes + size_t(pi) * 6;
    // The CPU evaluates glm::vec3(f(), f(), f()) and uniform_sphere_direction(f(), f()) arguments
    // right to left (g++): z first, then y, then x; u2 before u1.
    const float rz = rng.next_float(), ry = rng.next_float(), rx = rng.next_float();
    r.o = vec3(pb[0] + pb[3] * rx, pb[1] + pb[4] * ry, pb[2] + pb[5] * rz);
    const float u2 = rng.next_float(), u1 = rng.next_float();
    const float phi = 2.0f * 3.14159265358979323846f * u1;
    const float cos_theta = 2.0f * u2 - 1.0f;
    const float sin_theta = sqrtf(fmaxf(0.0f, 1.0f - cos_theta * cos_theta));
    r.d = vec3(sin_theta * cosf(phi), sin_theta * sinf(phi), cos_theta);
    const float dilation = 1e-5f + 1e-4f * rng.next_float();
    const uint32_t root = c.roots[r.cut * a.parts + pi];
    r.f = slab_ray_regular(r.d) ? first_leaf<true>(c.nodes, root, r.o, r.d, dilation, a.min_exit)
                                : first_leaf<false>(c.nodes, root, r.o, r.d, dilation, a.min_exit);
    r.kept = r.f.leaf >= 0;
    if (r.kept && r.cut == 0) {
        const float keep = c.keep[r.f.leaf];
        r.kept = !(keep < 1.0f && rng.next_float() >= keep);
    }
    return r;
}

// A slot's sample and its segment's encoded points (zero for a starved slot, leaf -1): everything the
// encode reads, so that it can run beside the batch's ground truth (cuda_core.cu).
__device__ void write_sample(const DevAsset& a, const DevBatch& b, uint32_t i, vec3 so, vec3 sd, float len,
                             int32_t leaf, uint32_t cut) {
    vec3 p0(0.0f), p1(0.0f), p2(0.0f);
    if (leaf >= 0) nb_segment_points(a.enc, so, sd, 0.0f, len, p0, p1, p2);
    float* pp = b.points + 9 * size_t(i);
    pp[0] = p0.x;
    pp[1] = p0.y;
    pp[2] = p0.z;
    pp[3] = p1.x;
    pp[4] = p1.y;
    pp[5] = p1.z;
    pp[6] = p2.x;
    pp[7] = p2.y;
    pp[8] = p2.z;
    b.origin[3 * i] = so.x; b.origin[3 * i + 1] = so.y; b.origin[3 * i + 2] = so.z;
    b.dir[3 * i] = sd.x; b.dir[3 * i + 1] = sd.y; b.dir[3 * i + 2] = sd.z;
    b.length[i] = len;
    b.leaf[i] = leaf;
    b.cut[i] = cut;
}

// Lanes l in [0, 32) with l % n == r.
__device__ uint32_t lanes_of_rank(uint32_t r, uint32_t n) {
    uint32_t m = 0u;
    for (uint32_t l = r; l < 32u; l += n) m |= 1u << l;
    return m;
}

// Position of the (k+1)-th set bit of m (m has more than k set bits).
__device__ uint32_t nth_set_bit(uint32_t m, uint32_t k) {
    for (uint32_t j = 0; j < k; ++j) m &= m - 1u;
    return uint32_t(__ffs(int(m)) - 1);
}

constexpr uint32_t kFullWarp = 0xFFFFFFFFu;

// Each lane owns one slot; a warp resolves its 32 slots together. Per round the n slots still open
// share the 32 lanes (lane l tries attempt next[slot] + l / n of the (l % n)-th open slot), so a slot
// that needs many redraws gets the lanes of the slots already done instead of leaving them idle (the
// per-slot loop this replaces cost a warp its slowest slot's redraw count). A slot's sample is its
// first kept attempt and only attempts up to it count as draws: the CPU loop's result, bit for bit.
// The body is a grid-stride loop although the launch covers the batch (one pass): in that form nvcc 13
// gave the kernel 48 registers instead of 68 (sm_90, no spills; 48 still with clip_regular and the
// nearer child in registers), 10 resident blocks per SM instead of 7, and the walks' stack loads more
// warps to hide behind:
// sampling 0.518 -> 0.473 ms on the H200 (results/cuda_training.md). Forcing fewer registers (launch
// bounds of 10, 12 or 16 blocks) spills and loses; drawing ahead with 8 blocks per SM looping over the
// batch lost too.
constexpr uint32_t kSampleBlock = 128; // whole warps: k_sample's lanes cooperate with full-mask intrinsics
static_assert(kSampleBlock % 32u == 0u, "k_sample needs whole warps");

__global__ void k_sample(DevAsset a, DevCuts c, DevBatch b, uint32_t batch, uint64_t seed, uint32_t step,
                         unsigned long long* draws_total, uint32_t* valid_total) {
    const uint32_t lane = threadIdx.x & 31u;
    uint32_t drawn = 0, valid = 0;
    for (uint32_t base = blockIdx.x * blockDim.x; base < batch; base += gridDim.x * blockDim.x) {
        const uint32_t slot = base + threadIdx.x;
        const uint32_t warp_base = slot - lane;
        bool open = slot < batch; // as the owner of `slot`
        uint32_t next = 0;        // as the owner: attempts taken so far
        for (;;) {
            const uint32_t open_mask = __ballot_sync(kFullWarp, open);
            if (open_mask == 0u) break;
            const uint32_t n = uint32_t(__popc(open_mask));
            // As an attempter: which slot, which attempt.
            const uint32_t rank = lane % n;
            const uint32_t owner = nth_set_bit(open_mask, rank);
            const uint32_t attempt = __shfl_sync(kFullWarp, next, owner) + lane / n;
            const bool active = attempt < kMaxSampleAttempts;
            Attempt r{};
            if (active) r = try_attempt(a, c, SampleSlot{seed, step, warp_base + owner}, attempt);
            const bool success = active && r.kept;
            const uint32_t wins = __ballot_sync(kFullWarp, success);
            const uint32_t mine = wins & lanes_of_rank(rank, n);
            const uint32_t first = mine ? uint32_t(__ffs(int(mine)) - 1) : 32u;
            if (active && lane <= first) { // attempts up to the slot's first kept one count
                drawn++;
                if (r.cut == 0u && r.f.leaf >= 0) atomicAdd(&c.leaf_draws[r.f.leaf], 1u);
            }
            if (success && lane == first)
                write_sample(a, b, warp_base + owner, r.o + r.d * r.f.t_entry, r.d,
                             fmaxf(r.f.t_exit - r.f.t_entry, 0.0f), r.f.leaf, r.cut);
            if (open) { // as the owner: done, or the attempts this round took
                const uint32_t my_rank = uint32_t(__popc(open_mask & ((1u << lane) - 1u)));
                const uint32_t lanes = lanes_of_rank(my_rank, n);
                if (wins & lanes) {
                    open = false;
                    valid++;
                } else {
                    next += uint32_t(__popc(lanes));
                    if (next >= kMaxSampleAttempts) { // starved: no reachable leaf
                        open = false;
                        write_sample(a, b, slot, vec3(0.0f), vec3(0.0f), 0.0f, -1, 0u);
                    }
                }
            }
        }
    }
    drawn = __reduce_add_sync(kFullWarp, drawn);
    valid = __reduce_add_sync(kFullWarp, valid);
    if (lane == 0u) {
        atomicAdd(draws_total, (unsigned long long)drawn);
        if (valid) atomicAdd(valid_total, valid);
    }
}

__device__ vec3 load3(const float* p) { return vec3(p[0], p[1], p[2]); }
// Triangle data through the read-only cache.
__device__ vec3 ldg3(const float* p) { return vec3(__ldg(p), __ldg(p + 1), __ldg(p + 2)); }

// The triangle BLAS's 4-wide nodes (shaders/shared/wide_bvh_node.h) through the read-only cache in four
// 16-byte loads. GpuWideNode is only 4-byte aligned in C++ (vec3 members), so `nodes[i]` would compile
// to 16 scalar loads (the binary nodes' copy did: results/cuda_training.md); the buffer is cudaMalloc'd
// and a node is 64 bytes, so every node is 16-byte aligned. NB_TRAVERSE_WIDE indexes this like an array.
struct WideNodes {
    const GpuWideNode* p;
    __device__ GpuWideNode operator[](uint32_t i) const {
        const uint4* q = reinterpret_cast<const uint4*>(p + i);
        const uint4 a = __ldg(q), b = __ldg(q + 1), c = __ldg(q + 2), d = __ldg(q + 3);
        GpuWideNode n;
        n.origin = vec3(__uint_as_float(a.x), __uint_as_float(a.y), __uint_as_float(a.z));
        n.child0 = a.w;
        n.scale = vec3(__uint_as_float(b.x), __uint_as_float(b.y), __uint_as_float(b.z));
        n.child1 = b.w;
        n.qlo_x = c.x;
        n.qlo_y = c.y;
        n.qlo_z = c.z;
        n.child2 = c.w;
        n.qhi_x = d.x;
        n.qhi_y = d.y;
        n.qhi_z = d.z;
        n.child3 = d.w;
        return n;
    }
};

// The texel footprint of a bilinear lookup at (u, v): engine/scene/texture_sampler.cpp
// sample_texture_bilinear (texel centres at +0.5, REPEAT wrap).
struct Footprint {
    uint32_t i00, i10, i01, i11; // texel indices
    float ax, ay;                // weights of the second column / row
};
__device__ Footprint footprint(const DevAsset& a, int32_t tex, float u, float v) {
    const uint32_t first = a.tex_info[3 * tex], w = a.tex_info[3 * tex + 1], h = a.tex_info[3 * tex + 2];
    if (!isfinite(u) || !isfinite(v)) u = v = 0.0f;
    u -= floorf(u);
    v -= floorf(v);
    const float x = u * float(w) - 0.5f, y = v * float(h) - 0.5f;
    const float fx = floorf(x), fy = floorf(y);
    auto wrap = [](int i, int n) { const int m = i % n; return m < 0 ? m + n : m; };
    const int x0 = wrap(int(fx), int(w)), y0 = wrap(int(fy), int(h));
    const int x1 = wrap(x0 + 1, int(w)), y1 = wrap(y0 + 1, int(h));
    const uint32_t r0 = first + uint32_t(y0) * w, r1 = first + uint32_t(y1) * w;
    return Footprint{r0 + uint32_t(x0), r0 + uint32_t(x1), r1 + uint32_t(x0), r1 + uint32_t(x1), x - fx, y - fy};
}

// The bilinear mix of texel(i) (float or vec3) over footprint f, in glm::mix's operation order.
template <class Texel>
__device__ auto bilerp(const Footprint& f, Texel texel) {
    const auto top = texel(f.i00) * (1.0f - f.ax) + texel(f.i10) * f.ax;
    const auto bottom = texel(f.i01) * (1.0f - f.ax) + texel(f.i11) * f.ax;
    return top * (1.0f - f.ay) + bottom * f.ay;
}

// Interpolated base-colour uv of triangle p (leaf order) at barycentrics (u, v).
__device__ void triangle_uv(const DevAsset& a, uint32_t p, float u, float v, float& uu, float& vv) {
    const float* tu = a.tri_uv + size_t(p) * 6;
    const float w = 1.0f - u - v;
    uu = tu[0] * w + tu[2] * u + tu[4] * v;
    vv = tu[1] * w + tu[3] * u + tu[5] * v;
}

// Base-colour alpha of triangle p (leaf order, coverage c) at (u, v): factor x the texture's alpha
// (bilinear, as the CPU sampler).
__device__ float surface_alpha(const DevAsset& a, const TriCoverage& c, uint32_t p, float u, float v) {
    float alpha = c.factor;
    const int32_t tex = a.tri_tex[p];
    if (tex >= 0) {
        float uu, vv;
        triangle_uv(a, p, u, v, uu, vv);
        alpha *= bilerp(footprint(a, tex, uu, vv), [&](uint32_t i) { return float(a.texels[i] >> 24) / 255.0f; });
    }
    return alpha;
}

// trainer/ground_truth.cpp blended_back_face: a single-sided blended triangle seen from behind.
__device__ bool blended_back_face(const TriCoverage& c, bool back_facing) {
    return c.mode == NB_ALPHA_BLEND && c.single_sided != 0u && back_facing;
}

// trainer/ground_truth.cpp alpha_covers for triangle p (leaf order, coverage c): the shared rule and the
// same draw.
__device__ bool covers(const DevAsset& a, const TriCoverage& c, uint32_t p, float u, float v, bool back_facing,
                       const SampleSlot& key) {
    if (c.mode == NB_ALPHA_OPAQUE) return true;
    if (blended_back_face(c, back_facing)) return false;
    return nb_alpha_covers(c.mode, surface_alpha(a, c, p, u, v), c.cutoff, key.coverage_bits(c.triangle));
}

// Walks the asset's 4-wide BLAS over [tmin, best] (NB_TRAVERSE_WIDE, the renderer's own loop: nearest
// child first) and calls crossing(p, tt, uu, vv, back_facing) for every triangle the ray crosses there
// (p in leaf order: the wide layout keeps the binary BVH's leaves); a crossing that returns true sets
// best = tt (later ones must be nearer). The CPU's ground truth walks the binary BVH: the same closest
// crossing (up to exact ties in t), and where no crossing stops the ray (stop_probability) the same
// crossings in another order. H200: ground truth 0.307 -> 0.256 ms per 2^18 samples (results/cuda_training.md).
template <class Crossing>
__device__ void walk(const DevAsset& a, vec3 o, vec3 d, float tmin, float& best, Crossing crossing) {
    const vec3 inv = nb_safe_inv_dir(d);
    const WideNodes nodes{a.mesh_wide};
    const bool done = false;
    auto leaf = [&](uint32_t first, uint32_t count) {
        for (uint32_t p = first; p < first + count; ++p) {
            const float* tv = a.tri_v + size_t(p) * 9;
            const vec3 v0 = ldg3(tv), v1 = ldg3(tv + 3), v2 = ldg3(tv + 6);
            float tt, uu, vv;
            if (nb_intersect_triangle(o, d, v0, v1, v2, tmin, best, tt, uu, vv) &&
                crossing(p, tt, uu, vv, nb_back_facing(v0, v1, v2, d)))
                best = tt;
        }
    };
    NB_TRAVERSE_WIDE(nodes, 0u, o, inv, tmin, best, done, leaf)
}

// Closest hit in [tmin, tmax] that alpha keeps (trainer/ground_truth.cpp closest_triangle_hit).
// `blended`: the hit, or with no hit some crossing the walk met, is an alpha-blended one (only then
// does the stop probability need its own walk: else it is 1 with a hit, 0 without).
__device__ bool closest_hit(const DevAsset& a, vec3 o, vec3 d, float tmin, float tmax, const SampleSlot& key,
                            float& t, uint32_t& tri, float& u, float& v, bool& blended) {
    bool hit = false, hit_blended = false, met_blended = false;
    float best = tmax;
    walk(a, o, d, tmin, best, [&](uint32_t p, float tt, float uu, float vv, bool back_facing) {
        bool blend = false;
        if (a.coverage) {
            const TriCoverage c = a.coverage[p];
            blend = c.mode == NB_ALPHA_BLEND;
            met_blended = met_blended || blend;
            if (!covers(a, c, p, uu, vv, back_facing, key)) return false;
        }
        t = tt; u = uu; v = vv; tri = p; hit = true;
        hit_blended = blend;
        return true;
    });
    blended = hit ? hit_blended : met_blended;
    return hit;
}

// trainer/ground_truth.cpp stop_probability: 1 at an opaque or kept MASK crossing, else 1 - prod(1 -
// alpha) over the blended crossings; the nearest blended crossing (nt infinite: none).
__device__ float stop_probability(const DevAsset& a, vec3 o, vec3 d, float tmin, float tmax, float& nt,
                                  uint32_t& ntri, float& nu, float& nv) {
    float pass = 1.0f, best = tmax;
    bool solid = false;
    nt = NB_INF;
    walk(a, o, d, tmin, best, [&](uint32_t p, float tt, float uu, float vv, bool back_facing) {
        const TriCoverage c = a.coverage[p];
        if (c.mode == NB_ALPHA_OPAQUE) {
            solid = true;
            return true;
        }
        if (blended_back_face(c, back_facing)) return false;
        const float alpha = surface_alpha(a, c, p, uu, vv);
        if (c.mode == NB_ALPHA_MASK) { // the shared rule; a MASK test draws nothing
            const bool kept = nb_alpha_covers(NB_ALPHA_MASK, alpha, c.cutoff, 0u);
            solid = solid || kept;
            return kept;
        }
        pass *= 1.0f - (isfinite(alpha) ? fminf(fmaxf(alpha, 0.0f), 1.0f) : 0.0f);
        if (tt < nt) { nt = tt; ntri = p; nu = uu; nv = vv; }
        return false;
    });
    return solid ? 1.0f : 1.0f - pass;
}

// engine/scene/texture_sampler.cpp sample_texture_bilinear with srgb = true, RGB only (same float
// operations: sRGB decoded per texel through the same table, then filtered; REPEAT wrap).
__device__ vec3 sample_base_colour(const DevAsset& a, int32_t tex, float u, float v) {
    return bilerp(footprint(a, tex, u, v), [&](uint32_t i) {
        const uint32_t c = a.texels[i];
        return vec3(a.srgb[c & 0xFFu], a.srgb[(c >> 8) & 0xFFu], a.srgb[(c >> 16) & 0xFFu]);
    });
}

// trainer/ground_truth.cpp shading_normal's normal map: the texture read linear (bilinear, as the CPU
// sampler with srgb = false), the shared tangent-space rule.
__device__ vec3 normal_mapped(const DevAsset& a, uint32_t p, float u, float v, vec3 n) {
    const TriNormalMap& nm = a.normal_maps[p];
    if (nm.texture < 0) return n;
    const float w = 1.0f - u - v;
    const Footprint f = footprint(a, nm.texture, nm.uv[0] * w + nm.uv[2] * u + nm.uv[4] * v,
                                  nm.uv[1] * w + nm.uv[3] * u + nm.uv[5] * v);
    const vec3 texel = bilerp(f, [&](uint32_t i) {
        const uint32_t c = a.texels[i];
        return vec3(float(c & 0xFFu) / 255.0f, float((c >> 8) & 0xFFu) / 255.0f, float((c >> 16) & 0xFFu) / 255.0f);
    });
    const float* t = nm.tangent;
    const vec4 t4(t[0] * w + t[4] * u + t[8] * v, t[1] * w + t[5] * u + t[9] * v, t[2] * w + t[6] * u + t[10] * v,
                  t[3] * w + t[7] * u + t[11] * v);
    return nb_normal_map(n, t4, texel, nm.scale);
}

// At most 64 registers (8 blocks of 128 per SM instead of 6 at the 80 the compiler picks; 16 bytes
// spilled): the walk waits on its node loads, and 2 more warps per scheduler hide more of them
// (H200: ground truth 0.257 -> 0.245 ms; 10 or 12 blocks spill 176 / 336 bytes and lose).
__global__ void __launch_bounds__(128, 8)
    k_ground_truth(DevAsset a, DevBatch b, uint64_t seed, uint32_t step) {
    const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= b.n) return;
    float tg[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    const vec3 o = load3(b.origin + 3 * i), d = load3(b.dir + 3 * i);
    const float len = b.length[i];
    if (b.leaf[i] >= 0) {
        float t = 0.0f, u = 0.0f, v = 0.0f;
        uint32_t tri = 0;
        bool blended = false;
        const bool drawn =
            a.mesh_wide && closest_hit(a, o, d, 0.0f, len, SampleSlot{seed, step, i}, t, tri, u, v, blended);
        float visibility = drawn ? 1.0f : 0.0f;
        if (a.mesh_wide && a.coverage && blended) { // soft target: the stop probability (ground_truth.h)
            float nt, nu, nv;
            uint32_t ntri = 0;
            visibility = stop_probability(a, o, d, 0.0f, len, nt, ntri, nu, nv);
            if (!drawn && visibility > 0.0f) { t = nt; tri = ntri; u = nu; v = nv; }
        }
        if (visibility > 0.0f) {
            const float w = 1.0f - u - v;
            const float* tn = a.tri_n + size_t(tri) * 9;
            vec3 n = load3(tn) * w + load3(tn + 3) * u + load3(tn + 6) * v;
            const float nl = length(n);
            if (nl > 1e-12f && isfinite(nl)) {
                n = n / nl;
                if (a.normal_maps) n = normal_mapped(a, tri, u, v, n);
            } else {
                n = load3(a.tri_g + size_t(tri) * 3);
            }
            const float* ta = a.tri_a + size_t(tri) * 9;
            vec3 al = load3(ta) * w + load3(ta + 3) * u + load3(ta + 6) * v;
            const int32_t tex = a.tri_tex[tri];
            if (tex >= 0) {
                float uu, vv;
                triangle_uv(a, tri, u, v, uu, vv);
                const vec3 c = sample_base_colour(a, tex, uu, vv);
                al = vec3(al.x * c.x, al.y * c.y, al.z * c.z);
            }
            al = clamp(al, vec3(0.0f), vec3(1.0f));
            tg[0] = visibility;
            tg[1] = nb_encode_depth_target(a.enc, t, 0.0f, len, false);
            tg[2] = (n.x + 1.0f) * 0.5f; tg[3] = (n.y + 1.0f) * 0.5f; tg[4] = (n.z + 1.0f) * 0.5f;
            tg[5] = al.x; tg[6] = al.y; tg[7] = al.z;
        }
    }
    for (int k = 0; k < 8; ++k) b.target[8 * i + k] = tg[k];
}

} // namespace

void launch_sample(const DevAsset& a, const DevCuts& c, const DevBatch& b, uint32_t batch, uint64_t seed,
                   uint32_t step, unsigned long long* draws, uint32_t* valid, cudaStream_t s) {
    // Whole warps: k_sample's lanes cooperate (slots past the batch start resolved).
    k_sample<<<(batch + kSampleBlock - 1) / kSampleBlock, kSampleBlock, 0, s>>>(a, c, b, batch, seed, step, draws, valid);
    NBVH_CUDA_CHECK(cudaGetLastError());
}

void launch_ground_truth(const DevAsset& a, const DevBatch& b, uint64_t seed, uint32_t step, cudaStream_t s) {
    k_ground_truth<<<(b.n + 127) / 128, 128, 0, s>>>(a, b, seed, step);
    NBVH_CUDA_CHECK(cudaGetLastError());
}

} // namespace nbvh::cuda
