// The neural ray query around the network (paper §3-4, official notes §1, §3): which 3 points of the
// ray/leaf segment are encoded, how they map into the asset's encoding box, and how the 8 outputs
// decode into a hit. The network itself: hashgrid.h (features) and mlp.h (weights, activations).
//
// Segment encoding: [t_entry, t_exit] is the slab interval of the ray with the (1e-5 dilated) leaf box,
// computed with mint = -inf, so t_entry < 0 means the origin is inside the leaf. Outside: the query
// runs entry -> exit. Inside ("reversed"): it runs exit -> entry (the network then predicts the LAST
// surface along the forward ray) and only hits more than depth_eps * L + fixed_eps in front of the
// origin are accepted (self-intersection guard of secondary rays starting on a neural surface).
//   e_a = enc(ray(t_start)), e_b = enc(ray(t_end)), point k = (1 - s_k) e_a + s_k e_b, s = 0, 1/2, 1
//   enc(p) = (p - C) / E' + 0.5, E' = guarded extent * (1 + 1.1e-4)  (per axis, anisotropic)
// Outputs (all after the sigmoid, y in (0,1)):
//   y0 visibility (hit if y0 > threshold, 0.5), y1 depth u: t = t_start +/- clamp(u,0,1) * (L + pad),
//   y2..4 normal: n = normalize(2y - 1), y5..7 albedo (linear base colour, used directly).
// Normals: we ADOPT the official "linearised normals" training (losses compare 10y - 4.5 with
// (n+1)/2, so trained outputs sit in [0.45, 0.55], in the sigmoid's linear region). The decode
// normalize(2y - 1) is the same with or without it (2y - 1 = n/10), so official weights trained either
// way decode correctly; see engine/neural/losses.h.
#ifndef NB_NEURAL_QUERY_H
#define NB_NEURAL_QUERY_H
#include "compat.h"
#include "neural_config.h"

// Encoding normalisation: node_extent_dilation (1e-4) + fixed_node_dilation (1e-5) of the official
// code, so training points on dilated leaf boxes stay inside [0,1]^3.
#define NB_ENC_DILATION 1.1e-4f
// Zero-extent guard (flat assets, e.g. a plane): each axis of the encoding box is padded to at least
// NB_ENC_MIN_EXTENT_REL x the largest axis extent, and every axis to at least
// NB_ENC_MIN_EXTENT_ABS_REL x (largest |centre| coordinate) and NB_ENC_MIN_EXTENT_FLOOR, so a point
// asset or a box far from the origin still gets a finite, representable divisor. Padding only
// enlarges the box: points of the asset stay inside [0,1]^3.
#define NB_ENC_MIN_EXTENT_REL 1e-3f
#define NB_ENC_MIN_EXTENT_ABS_REL 1e-6f
#define NB_ENC_MIN_EXTENT_FLOOR 1e-20f
// Encoded coordinates are clamped (NaN -> low bound) to this range before the grid lookup. Valid
// queries lie in [-1e-3, 1.001], so the clamp never changes them; it keeps int(floor()) defined.
#define NB_ENC_CLAMP_LO -1.0f
#define NB_ENC_CLAMP_HI 2.0f
// Decode defaults (official: primary/secondary visibility thresholds, depth_epsilon,
// fixed_depth_epsilon, the +1e-3 depth normaliser pad). Pad and fixed epsilon are object-space
// units (the official constants are absolute, tuned for ~unit-size scenes); they are stored per asset
// in GpuEncodingBox so a model can scale them.
#define NB_VISIBILITY_THRESHOLD 0.5f
#define NB_DEPTH_EPSILON 0.2f
#define NB_FIXED_DEPTH_EPSILON 1e-5f
#define NB_DEPTH_PAD 1e-3f

// The encoding box of one neural asset (object space), 32 bytes, stored in the model file.
struct GpuEncodingBox {
    vec3 center;           // C
    float depth_pad;       // depth normaliser: u = (t_hit - t_start) / (L + depth_pad)
    vec3 extent;           // E' = guarded extent * (1 + NB_ENC_DILATION), > 0 on every axis
    float fixed_depth_eps; // inside-origin absolute margin
};
NB_STATIC_ASSERT(sizeof(GpuEncodingBox) == 32, "GpuEncodingBox must be 32 bytes");

// Build the encoding box from the asset's object-space bounds (computed once, when the model is
// created; readers use the stored values).
NB_FN GpuEncodingBox nb_make_encoding_box(vec3 lo, vec3 hi) {
    GpuEncodingBox b;
    b.center = (lo + hi) * 0.5f;
    vec3 e = hi - lo;
    float ex = max(e.x, 0.0f);
    float ey = max(e.y, 0.0f);
    float ez = max(e.z, 0.0f);
    float emax = max(ex, max(ey, ez));
    float cmax = max(abs(b.center.x), max(abs(b.center.y), abs(b.center.z)));
    float emin = max(NB_ENC_MIN_EXTENT_REL * emax,
                     max(NB_ENC_MIN_EXTENT_ABS_REL * cmax, NB_ENC_MIN_EXTENT_FLOOR));
    float scale = 1.0f + NB_ENC_DILATION;
    b.extent = vec3(max(ex, emin) * scale, max(ey, emin) * scale, max(ez, emin) * scale);
    b.depth_pad = NB_DEPTH_PAD;
    b.fixed_depth_eps = NB_FIXED_DEPTH_EPSILON;
    return b;
}

// NaN-safe clamp (a NaN compares false and goes to lo).
NB_FN float nb_clamp_safe(float x, float lo, float hi) { return x >= lo ? (x <= hi ? x : hi) : lo; }

// enc(p) = (p - C) / E' + 0.5 per axis, clamped to [NB_ENC_CLAMP_LO, NB_ENC_CLAMP_HI].
NB_FN vec3 nb_encode_point(GpuEncodingBox box, vec3 p) {
    vec3 e = (p - box.center) / box.extent + vec3(0.5f);
    return vec3(nb_clamp_safe(e.x, NB_ENC_CLAMP_LO, NB_ENC_CLAMP_HI),
                nb_clamp_safe(e.y, NB_ENC_CLAMP_LO, NB_ENC_CLAMP_HI),
                nb_clamp_safe(e.z, NB_ENC_CLAMP_LO, NB_ENC_CLAMP_HI));
}

// True when the origin is inside the leaf and the reversed segment must be queried.
NB_FN bool nb_query_reversed(float t_entry) { return t_entry < 0.0f; }

// The 3 encoded points of the query, in query order (p0 = start of the query). Returns `reversed`.
NB_FN bool nb_segment_points(GpuEncodingBox box, vec3 ro, vec3 rd, float t_entry, float t_exit,
                             NB_OUT(vec3) p0, NB_OUT(vec3) p1, NB_OUT(vec3) p2) {
    bool rev = nb_query_reversed(t_entry);
    float ta = rev ? t_exit : t_entry;
    float tb = rev ? t_entry : t_exit;
    vec3 ea = nb_encode_point(box, ro + rd * ta);
    vec3 eb = nb_encode_point(box, ro + rd * tb);
    p0 = ea;
    p1 = ea * 0.5f + eb * 0.5f;
    p2 = eb;
    return rev;
}

NB_FN bool nb_decode_visibility(float y0, float threshold) { return y0 > threshold; }

// Back-face escape (a departure from the paper and the official code; engine/render/NEURAL.md). A ray
// that leaves a neural hit seen from behind (its predicted normal faced along the incoming ray: the
// first test below, with cosine 0) carries NB_RAY_BACKFACE_BIT (shared/wavefront_gpu.h). Such hits come
// mostly from the reversed query of the leaf a ray starts in, which answers the LAST surface of the
// leaf: the far side of a part the ray crosses. Shaded there with the normal turned towards the ray,
// the path reflects into the part and bounces inside it, and its shadow rays are blocked by the part's
// own back faces. A flagged ray skips hits whose predicted normal n faces along its direction d by
// more than NB_BACKFACE_ESCAPE_COS: shadow rays in every leaf, path rays only in the leaf they start in
// (reversed queries), so that neither leaks through other parts seen from behind (thin strands), which
// measured worse on the default scene's rope (results/perf/README.md, back-face escape). The
// cosine keeps hits whose predicted normal is merely grazing (normal error on bumpy surfaces).
#define NB_BACKFACE_ESCAPE_COS 0.3f

// True when the predicted normal n faces along direction d by more than cosine c (any lengths; false
// for zero or non-finite vectors).
NB_FN bool nb_faces_along(vec3 n, vec3 d, float c) {
    float nd = dot(n, d);
    float len2 = dot(n, n) * dot(d, d);
    if (!(len2 > 0.0f) || !(len2 < 3.0e38f)) return false;
    return nd > 0.0f && nd * nd > c * c * len2;
}

// True when a flagged ray (NB_RAY_BACKFACE_BIT) skips this query's hit with predicted normal n.
NB_FN bool nb_backface_skip(bool flagged, bool shadow_ray, bool reversed, vec3 n, vec3 d) {
    return flagged && (shadow_ray || reversed) && nb_faces_along(n, d, NB_BACKFACE_ESCAPE_COS);
}

// Depth decode (LocalT). Returns false when the inside-origin margin rejects the hit; t_hit is the ray
// parameter of the hit along the FORWARD ray either way.
// dir_len: the length of the ray direction in the encoding (object) space. The box's depth_pad and
// fixed_depth_eps are object-space lengths and training rays have unit directions there, while the
// renderer's rays keep their world-space parameter (object direction of length 1 / the instance's
// scale): the pads are converted to ray-parameter units by 1 / dir_len. (Without it the pad grew
// relative to the leaf as an instance shrank: hit depths pushed up to ~20 % of a leaf deeper on Chess's
// 5 cm pieces, and the same model rendered differently at 0.1 m and 1 m.) A non-positive or NaN dir_len
// counts as 1.
NB_FN bool nb_decode_depth(GpuEncodingBox box, float y1, float t_entry, float t_exit, float dir_len,
                           NB_OUT(float) t_hit) {
    float u = nb_clamp_safe(y1, 0.0f, 1.0f);
    float len = max(t_exit - t_entry, 0.0f);
    float to_t = dir_len > 0.0f ? 1.0f / dir_len : 1.0f;
    float d = u * (len + box.depth_pad * to_t);
    if (nb_query_reversed(t_entry)) {
        t_hit = t_exit - d;
        return d < t_exit - NB_DEPTH_EPSILON * len - box.fixed_depth_eps * to_t;
    }
    t_hit = t_entry + d;
    return true;
}

// Training target of the depth output for a hit at t_hit (forward ray parameter) inside the query.
// Training rays have unit directions in the encoding space (t is an object-space length).
NB_FN float nb_encode_depth_target(GpuEncodingBox box, float t_hit, float t_entry, float t_exit,
                                   bool reversed) {
    float len = max(t_exit - t_entry, 0.0f);
    float d = reversed ? (t_exit - t_hit) : (t_hit - t_entry);
    return nb_clamp_safe(d / (len + box.depth_pad), 0.0f, 1.0f);
}

// Normal decode: normalize(2y - 1); a degenerate (all 0.5) prediction gives +z instead of NaN.
NB_FN vec3 nb_decode_normal(float y2, float y3, float y4) {
    vec3 n = vec3(2.0f * y2 - 1.0f, 2.0f * y3 - 1.0f, 2.0f * y4 - 1.0f);
    float l2 = dot(n, n);
    if (!(l2 > 1e-30f)) {
        return vec3(0.0f, 0.0f, 1.0f);
    }
    return n * inversesqrt(l2);
}

#endif // NB_NEURAL_QUERY_H
