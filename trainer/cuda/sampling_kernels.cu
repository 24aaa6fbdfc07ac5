// Training-ray generation with the first-leaf search over the current N-BVH cut (paper §3, §3.3;
// mirrors trainer/training_rays.cpp and cpu_backend.cpp draw_training_sample), and the ground truth
// of each sample by a closest-hit traversal of the asset's triangle BVH in the shared GpuBvhNode layout
// with the shared ray/box and ray/triangle tests (shaders/shared/intersect.h).
// Compiled with --fmad=false (CMakeLists.txt) so the ray set matches the CPU backend's for a seed.
#include "trainer/cuda/clip_box.cuh"
#include "trainer/cuda/device_common.cuh"

namespace nbvh::cuda {
namespace {

struct Found { int32_t leaf; float t_entry, t_exit; };

// first_leaf_of_cut: nearest-first descent of the base BVH, stopping at cut leaves.
__device__ Found first_leaf(const DevAsset& a, const int32_t* leaf_of, vec3 o, vec3 d, float dilation, uint32_t root) {
    Found best{-1, 0.0f, 0.0f};
    const InvDir id = inv_dir(d);
    float best_entry = NB_INF;
    uint32_t st_node[NB_BVH_MAX_DEPTH * 2 + 2];
    float st_t[NB_BVH_MAX_DEPTH * 2 + 2];
    int top = 0;
    float t0, t1;
    if (a.base_nodes == 0) return best;
    if (!clip_dilated(a.node_boxes + size_t(root) * 6, o, d, id, dilation, t0, t1) || t1 <= a.min_exit) return best;
    st_node[top] = root;
    st_t[top++] = t0;
    while (top > 0) {
        --top;
        const uint32_t node = st_node[top];
        const float te = st_t[top];
        if (te >= best_entry) continue;
        const int32_t slot = leaf_of[node];
        if (slot >= 0) {
            float ea = 0.0f, eb = 0.0f;
            clip_dilated(a.node_boxes + size_t(node) * 6, o, d, id, dilation, ea, eb);
            best = Found{slot, ea, eb};
            best_entry = te;
            continue;
        }
        const uint2 ch = a.children[node];
        if (ch.x == 0xFFFFFFFFu && ch.y == 0xFFFFFFFFu) continue; // base leaf below no cut leaf
        uint32_t kn[2];
        float kt[2];
        int count = 0;
        const uint32_t kids[2] = {ch.x, ch.y};
        for (int k = 0; k < 2; ++k) {
            const uint32_t child = kids[k];
            if (child == 0xFFFFFFFFu) continue;
            if (clip_dilated(a.node_boxes + size_t(child) * 6, o, d, id, dilation, t0, t1) && t1 > a.min_exit &&
                t0 < best_entry) {
                kn[count] = child;
                kt[count++] = t0;
            }
        }
        if (count == 2 && kt[0] < kt[1]) {
            const uint32_t n = kn[0]; kn[0] = kn[1]; kn[1] = n;
            const float t = kt[0]; kt[0] = kt[1]; kt[1] = t;
        }
        if (top + count > int(NB_BVH_MAX_DEPTH * 2 + 2)) return best; // cannot happen for a valid BVH
        for (int k = 0; k < count; ++k) {
            st_node[top] = kn[k];
            st_t[top++] = kt[k];
        }
    }
    return best;
}

__global__ void k_sample(DevAsset a, DevCuts c, DevBatch b, uint32_t batch, uint64_t seed, uint32_t step,
                         unsigned long long* draws_total, uint32_t* valid_total) {
    const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= batch) return;
    DevPcg32 rng(seed ^ (uint64_t(step) * 0x9E3779B97F4A7C15ull), i);
    uint32_t draws = 0;
    int32_t leaf = -1;
    uint32_t cut = 0;
    vec3 so(0.0f), sd(0.0f);
    float len = 0.0f;
    const uint32_t max_draws = 100000u;
    for (uint32_t attempt = 0; attempt < max_draws; ++attempt) {
        draws++;
        const uint32_t ci = c.count > 1 ? min(uint32_t(rng.next_float() * float(c.count)), c.count - 1u) : 0u;
        // The part (trainer/training_asset.h pick_part; drawn only when there are several).
        const uint32_t pi = a.parts > 1 ? min(uint32_t(rng.next_float() * float(a.parts)), a.parts - 1u) : 0u;
        const float* pb = a.part_boxes + size_t(pi) * 6;
        // The CPU evaluates glm::vec3(f(), f(), f()) and uniform_sphere_direction(f(), f()) arguments
        // right to left (g++): z first, then y, then x; u2 before u1.
        const float rz = rng.next_float(), ry = rng.next_float(), rx = rng.next_float();
        const vec3 o(pb[0] + pb[3] * rx, pb[1] + pb[4] * ry, pb[2] + pb[5] * rz);
        const float u2 = rng.next_float(), u1 = rng.next_float();
        const float phi = 2.0f * 3.14159265358979323846f * u1;
        const float cos_theta = 2.0f * u2 - 1.0f;
        const float sin_theta = sqrtf(fmaxf(0.0f, 1.0f - cos_theta * cos_theta));
        const vec3 d(sin_theta * cosf(phi), sin_theta * sinf(phi), cos_theta);
        const float dilation = 1e-5f + 1e-4f * rng.next_float();
        const Found f = first_leaf(a, c.leaf_of[ci], o, d, dilation, a.part_roots[pi]);
        if (f.leaf < 0) continue;
        if (ci == 0) {
            atomicAdd(&c.leaf_draws[f.leaf], 1u);
            const float keep = c.keep[f.leaf];
            if (keep < 1.0f && rng.next_float() >= keep) continue;
        }
        so = o + d * f.t_entry;
        sd = d;
        len = fmaxf(f.t_exit - f.t_entry, 0.0f);
        leaf = f.leaf;
        cut = ci;
        break;
    }
    b.origin[3 * i] = so.x; b.origin[3 * i + 1] = so.y; b.origin[3 * i + 2] = so.z;
    b.dir[3 * i] = sd.x; b.dir[3 * i + 1] = sd.y; b.dir[3 * i + 2] = sd.z;
    b.length[i] = len;
    b.leaf[i] = leaf;
    b.cut[i] = cut;
    atomicAdd(draws_total, (unsigned long long)draws);
    if (leaf >= 0) atomicAdd(valid_total, 1u);
}

__device__ vec3 load3(const float* p) { return vec3(p[0], p[1], p[2]); }

// Closest hit in [tmin, tmax] over the GpuBvhNode tree (nearest child first).
__device__ bool closest_hit(const DevAsset& a, vec3 o, vec3 d, float tmin, float tmax, float& t, uint32_t& tri,
                            float& u, float& v) {
    const vec3 inv = nb_safe_inv_dir(d);
    uint32_t stack[NB_BVH_MAX_DEPTH + 2];
    int top = 0;
    uint32_t node = 0;
    bool hit = false;
    float best = tmax;
    for (;;) {
        const GpuBvhNode n = a.mesh_nodes[node];
        float tl, tr;
        const bool hl = n.left != NB_CHILD_NONE && nb_intersect_aabb(o, inv, n.lmin, n.lmax, tmin, best, tl);
        const bool hr = n.right != NB_CHILD_NONE && nb_intersect_aabb(o, inv, n.rmin, n.rmax, tmin, best, tr);
        uint32_t refs[2];
        int cnt = 0;
        // Leaves are tested right away; interior children are pushed (far first).
        uint32_t inner[2];
        float inner_t[2];
        int ni = 0;
        if (hl) refs[cnt++] = n.left;
        if (hr) refs[cnt++] = n.right;
        for (int k = 0; k < cnt; ++k) {
            const uint32_t ref = refs[k];
            if (nb_is_leaf(ref)) {
                const uint32_t first = nb_leaf_first(ref), count = nb_leaf_count(ref);
                for (uint32_t p = first; p < first + count; ++p) {
                    const float* tv = a.tri_v + size_t(p) * 9;
                    float tt, uu, vv;
                    if (nb_intersect_triangle(o, d, load3(tv), load3(tv + 3), load3(tv + 6), tmin, best, tt, uu, vv)) {
                        best = tt; t = tt; u = uu; v = vv; tri = p; hit = true;
                    }
                }
            } else {
                inner[ni] = ref;
                inner_t[ni++] = (ref == n.left) ? tl : tr;
            }
        }
        if (ni == 2) {
            const bool swap = inner_t[1] < inner_t[0];
            const uint32_t nearer = swap ? inner[1] : inner[0], farther = swap ? inner[0] : inner[1];
            if (top < int(NB_BVH_MAX_DEPTH + 2)) stack[top++] = farther;
            node = nearer;
            continue;
        }
        if (ni == 1) { node = inner[0]; continue; }
        if (top == 0) break;
        node = stack[--top];
    }
    return hit;
}

// engine/scene/texture_sampler.cpp sample_texture_bilinear with srgb = true, RGB only (same float
// operations: sRGB decoded per texel through the same table, then filtered; REPEAT wrap).
__device__ vec3 sample_base_colour(const DevAsset& a, int32_t tex, float u, float v) {
    const uint32_t first = a.tex_info[3 * tex], w = a.tex_info[3 * tex + 1], h = a.tex_info[3 * tex + 2];
    if (!isfinite(u) || !isfinite(v)) u = v = 0.0f;
    u -= floorf(u);
    v -= floorf(v);
    const float x = u * float(w) - 0.5f, y = v * float(h) - 0.5f;
    const float fx = floorf(x), fy = floorf(y);
    const float ax = x - fx, ay = y - fy;
    auto wrap = [](int i, int n) { const int m = i % n; return m < 0 ? m + n : m; };
    const int x0 = wrap(int(fx), int(w)), y0 = wrap(int(fy), int(h));
    const int x1 = wrap(x0 + 1, int(w)), y1 = wrap(y0 + 1, int(h));
    auto texel = [&](int tx, int ty) {
        const uint32_t c = a.texels[first + uint32_t(ty) * w + uint32_t(tx)];
        return vec3(a.srgb[c & 0xFFu], a.srgb[(c >> 8) & 0xFFu], a.srgb[(c >> 16) & 0xFFu]);
    };
    // glm::mix(p, q, t) = p * (1 - t) + q * t
    const vec3 top = texel(x0, y0) * (1.0f - ax) + texel(x1, y0) * ax;
    const vec3 bottom = texel(x0, y1) * (1.0f - ax) + texel(x1, y1) * ax;
    return top * (1.0f - ay) + bottom * ay;
}

__global__ void k_ground_truth(DevAsset a, DevBatch b) {
    const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= b.n) return;
    float tg[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    const vec3 o = load3(b.origin + 3 * i), d = load3(b.dir + 3 * i);
    const float len = b.length[i];
    vec3 p0(0.0f), p1(0.0f), p2(0.0f);
    if (b.leaf[i] >= 0) {
        float t = 0.0f, u = 0.0f, v = 0.0f;
        uint32_t tri = 0;
        if (a.mesh_nodes && closest_hit(a, o, d, 0.0f, len, t, tri, u, v)) {
            const float w = 1.0f - u - v;
            const float* tn = a.tri_n + size_t(tri) * 9;
            vec3 n = load3(tn) * w + load3(tn + 3) * u + load3(tn + 6) * v;
            const float nl = length(n);
            n = (nl > 1e-12f && isfinite(nl)) ? n / nl : load3(a.tri_g + size_t(tri) * 3);
            const float* ta = a.tri_a + size_t(tri) * 9;
            vec3 al = load3(ta) * w + load3(ta + 3) * u + load3(ta + 6) * v;
            const int32_t tex = a.tri_tex[tri];
            if (tex >= 0) {
                const float* tu = a.tri_uv + size_t(tri) * 6;
                const float uu = tu[0] * w + tu[2] * u + tu[4] * v, vv = tu[1] * w + tu[3] * u + tu[5] * v;
                const vec3 c = sample_base_colour(a, tex, uu, vv);
                al = vec3(al.x * c.x, al.y * c.y, al.z * c.z);
            }
            al = clamp(al, vec3(0.0f), vec3(1.0f));
            tg[0] = 1.0f;
            tg[1] = nb_encode_depth_target(a.enc, t, 0.0f, len, false);
            tg[2] = (n.x + 1.0f) * 0.5f; tg[3] = (n.y + 1.0f) * 0.5f; tg[4] = (n.z + 1.0f) * 0.5f;
            tg[5] = al.x; tg[6] = al.y; tg[7] = al.z;
        }
        nb_segment_points(a.enc, o, d, 0.0f, len, p0, p1, p2);
    }
    for (int k = 0; k < 8; ++k) b.target[8 * i + k] = tg[k];
    float* pp = b.points + 9 * size_t(i);
    pp[0] = p0.x; pp[1] = p0.y; pp[2] = p0.z; pp[3] = p1.x; pp[4] = p1.y; pp[5] = p1.z;
    pp[6] = p2.x; pp[7] = p2.y; pp[8] = p2.z;
}

} // namespace

void launch_sample(const DevAsset& a, const DevCuts& c, const DevBatch& b, uint32_t batch, uint64_t seed,
                   uint32_t step, unsigned long long* draws, uint32_t* valid, cudaStream_t s) {
    k_sample<<<(batch + 127) / 128, 128, 0, s>>>(a, c, b, batch, seed, step, draws, valid);
    NBVH_CUDA_CHECK(cudaGetLastError());
}

void launch_ground_truth(const DevAsset& a, const DevBatch& b, cudaStream_t s) {
    k_ground_truth<<<(b.n + 127) / 128, 128, 0, s>>>(a, b);
    NBVH_CUDA_CHECK(cudaGetLastError());
}

} // namespace nbvh::cuda
