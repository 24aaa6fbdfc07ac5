// Random numbers, direction sampling, the glTF metallic-roughness BSDF pieces (Lambert + GGX) and
// the environment parameterisation, shared by the path-tracing shaders and the C++ tests that check
// them (pdf normalisation, determinism). Units: solid-angle pdfs in 1/sr.
#ifndef NB_SAMPLING_H
#define NB_SAMPLING_H
#include "compat.h"

#define NB_PI 3.14159265358979f
#define NB_INV_PI 0.318309886183791f

#ifdef NB_GLSL
#define nb_atan2(y, x) atan(y, x)
#else
NB_FN float nb_atan2(float y, float x) { return atan2f(y, x); }
#endif

// ---- Random numbers: PCG hash (Jarzynski & Olano 2020, "Hash Functions for GPU Rendering") ------
NB_FN uint nb_pcg_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// Sampler state of one path: independent per pixel, sample and --seed.
NB_FN uint nb_rng_init(uint pixel, uint sample_index, uint seed) {
    return nb_pcg_hash(pixel ^ nb_pcg_hash(sample_index ^ nb_pcg_hash(seed + 0x9E3779B9u)));
}

// Uniform float in [0, 1) with 24 bits; advances the state.
NB_FN float nb_rng_next(NB_INOUT(uint) state) {
    state = state * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    word = (word >> 22u) ^ word;
    return float(word >> 8u) * (1.0f / 16777216.0f);
}

// ---- Quasi-random numbers: shuffled, Owen-scrambled Sobol (Burley 2020, "Practical Hash-based Owen
// Scrambling", JCGT 9(4)) ------------------------------------------------------------------------------
// Each 2D sample dimension pair of a path (pixel jitter, a bounce's light sample, its BSDF sample, ...)
// takes the first two Sobol dimensions (a (0,2)-sequence), its index shuffled and its values scrambled
// by nested uniform (Owen) scrambling seeded per pixel and dimension: every power-of-two prefix of a
// pixel's samples is a stratified (0,m,2)-net in each pair, and the pairs are randomised independently
// ("padding": a product of functions of two pairs is not stratified jointly and may even have somewhat
// more variance than with independent numbers). Unbiased like independent samples; the variance of
// smooth integrands of one pair falls faster than 1/spp.
#ifdef NB_GLSL
#define nb_reverse_bits(x) bitfieldReverse(x)
#else
NB_FN uint nb_reverse_bits(uint x) {
    x = ((x >> 1u) & 0x55555555u) | ((x & 0x55555555u) << 1u);
    x = ((x >> 2u) & 0x33333333u) | ((x & 0x33333333u) << 2u);
    x = ((x >> 4u) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4u);
    x = ((x >> 8u) & 0x00FF00FFu) | ((x & 0x00FF00FFu) << 8u);
    return (x >> 16u) | (x << 16u);
}
#endif

// Burley's improved Laine-Karras permutation: bit j of the result depends only on bits <= j of x.
NB_FN uint nb_laine_karras(uint x, uint seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

// Nested uniform scramble of a 0.32 fixed-point value (bit 31 = 1/2): bit j flips as a function of
// the bits above it only.
NB_FN uint nb_owen_scramble(uint x, uint seed) {
    return nb_reverse_bits(nb_laine_karras(nb_reverse_bits(x), seed));
}

// Sobol dimension 1 in 0.32 fixed point; dimension 0 is the van der Corput sequence, nb_reverse_bits(i).
// Its generator matrix is Pascal's triangle mod 2: digit r of the result (bit 31 - r) is the XOR of the
// index bits c with C(c, r) odd, i.e. (Lucas) with r a bit-subset of c. That superset XOR over the 5-bit
// positions is one butterfly per position bit (a GF(2) zeta transform): no loop over the index bits.
NB_FN uint nb_sobol_dim1_digits(uint i) {
    i ^= (i >> 1u) & 0x55555555u;
    i ^= (i >> 2u) & 0x33333333u;
    i ^= (i >> 4u) & 0x0F0F0F0Fu;
    i ^= (i >> 8u) & 0x00FF00FFu;
    i ^= (i >> 16u) & 0x0000FFFFu;
    return i; // digit r at bit r
}
NB_FN uint nb_sobol_dim1(uint i) { return nb_reverse_bits(nb_sobol_dim1_digits(i)); }

// Seed of one sample dimension pair of one path: pixel seed (nb_qmc_pixel_seed), segment and pair.
NB_FN uint nb_qmc_pixel_seed(uint pixel, uint seed) {
    return nb_pcg_hash(pixel ^ nb_pcg_hash(seed + 0x7F4A7C15u));
}
NB_FN uint nb_qmc_dim_seed(uint pixel_seed, uint depth, uint pair) {
    return nb_pcg_hash(pixel_seed ^ nb_pcg_hash((depth << 4u) + pair));
}

// Point sample_index of the shuffled, scrambled 2D sequence of a dimension seed; in [0, 1)^2, 24 bits.
// nb_owen_scramble(nb_reverse_bits(i)) and nb_owen_scramble(nb_sobol_dim1(i)) with the reversals that
// cancel left out.
NB_FN vec2 nb_qmc_2d(uint sample_index, uint dim_seed) {
    uint i = nb_owen_scramble(sample_index, dim_seed);
    uint x = nb_reverse_bits(nb_laine_karras(i, nb_pcg_hash(dim_seed ^ 0xA3C59AC3u)));
    uint y = nb_reverse_bits(nb_laine_karras(nb_sobol_dim1_digits(i), nb_pcg_hash(dim_seed ^ 0x3C6EF372u)));
    return vec2(float(x >> 8u), float(y >> 8u)) * (1.0f / 16777216.0f);
}

// Sample reuse (pbrt-v4 §2.2.1): a uniform u that fell in [lo, lo + p) and chose that interval's option,
// rescaled to [0, 1) to serve as the chosen option's own number: when u is one coordinate of a net, the
// points that chose an option stay a net of the option's own (fewer points, the same stratification).
// Kept below 1 (p may be tiny, or u sit on the interval's far end by rounding).
NB_FN float nb_sample_reuse(float u, float lo, float p) { return min((u - lo) / p, 0.99999994f); }

// ---- Helpers --------------------------------------------------------------------------------------
NB_FN float nb_luminance(vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

NB_FN float nb_srgb_to_linear(float c) {
    return c <= 0.04045f ? c * (1.0f / 12.92f) : pow((c + 0.055f) * (1.0f / 1.055f), 2.4f);
}

// Orthonormal basis around unit n (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
NB_FN void nb_make_basis(vec3 n, NB_OUT(vec3) t, NB_OUT(vec3) b) {
    float s = n.z >= 0.0f ? 1.0f : -1.0f;
    float a = -1.0f / (s + n.z);
    float c = n.x * n.y * a;
    t = vec3(1.0f + s * n.x * n.x * a, s * c, -s * n.x);
    b = vec3(c, s + n.y * n.y * a, -n.y);
}

// Power heuristic with beta = 2 (Veach 1997), for one sample from each strategy.
NB_FN float nb_power_heuristic(float pdf_a, float pdf_b) {
    float a = pdf_a * pdf_a;
    float b = pdf_b * pdf_b;
    return a + b > 0.0f ? a / (a + b) : 0.0f;
}

// ---- Lambert ------------------------------------------------------------------------------------
// Cosine-weighted hemisphere around +z (local frame); pdf = cos(theta) / pi.
NB_FN vec3 nb_sample_cosine(float u1, float u2) {
    float r = sqrt(u1);
    float phi = 2.0f * NB_PI * u2;
    return vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0f, 1.0f - u1)));
}

// ---- GGX (Trowbridge-Reitz) with height-correlated Smith masking --------------------------------
// alpha = roughness^2 (glTF), clamped so that a perfect mirror stays numerically well-behaved.
NB_FN float nb_ggx_alpha(float roughness) { return max(1.0e-3f, roughness * roughness); }

NB_FN float nb_ggx_d(float n_dot_h, float alpha) {
    float a2 = alpha * alpha;
    float d = n_dot_h * n_dot_h * (a2 - 1.0f) + 1.0f;
    return a2 / max(NB_PI * d * d, 1.0e-20f);
}

// Visibility term V = G2 / (4 n.l n.v) (height-correlated, glTF spec appendix B).
NB_FN float nb_ggx_v(float n_dot_l, float n_dot_v, float alpha) {
    float a2 = alpha * alpha;
    float gv = n_dot_l * sqrt(n_dot_v * n_dot_v * (1.0f - a2) + a2);
    float gl = n_dot_v * sqrt(n_dot_l * n_dot_l * (1.0f - a2) + a2);
    return 0.5f / max(gv + gl, 1.0e-20f);
}

NB_FN float nb_ggx_g1(float n_dot_v, float alpha) {
    float a2 = alpha * alpha;
    return 2.0f * n_dot_v / max(n_dot_v + sqrt(a2 + (1.0f - a2) * n_dot_v * n_dot_v), 1.0e-20f);
}

// Visible-normal sampling (Heitz 2018, "Sampling the GGX Distribution of Visible Normals"); wo and the
// returned half vector are in the local frame (+z = normal).
NB_FN vec3 nb_ggx_sample_vndf(vec3 wo, float alpha, float u1, float u2) {
    vec3 vh = normalize(vec3(alpha * wo.x, alpha * wo.y, wo.z));
    float lensq = vh.x * vh.x + vh.y * vh.y;
    vec3 t1 = lensq > 0.0f ? vec3(-vh.y, vh.x, 0.0f) * inversesqrt(lensq) : vec3(1.0f, 0.0f, 0.0f);
    vec3 t2 = cross(vh, t1);
    float r = sqrt(u1);
    float phi = 2.0f * NB_PI * u2;
    float p1 = r * cos(phi);
    float p2 = r * sin(phi);
    float s = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - s) * sqrt(max(0.0f, 1.0f - p1 * p1)) + s * p2;
    vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
    return normalize(vec3(alpha * nh.x, alpha * nh.y, max(1.0e-6f, nh.z)));
}

// Solid-angle pdf of a reflected direction produced by nb_ggx_sample_vndf: G1(wo) D(h) / (4 n.v).
NB_FN float nb_ggx_pdf(float n_dot_v, float n_dot_h, float alpha) {
    return nb_ggx_g1(n_dot_v, alpha) * nb_ggx_d(n_dot_h, alpha) / max(4.0f * n_dot_v, 1.0e-20f);
}

NB_FN vec3 nb_fresnel_schlick(vec3 f0, float cos_theta) {
    float m = clamp(1.0f - cos_theta, 0.0f, 1.0f);
    float m5 = m * m * m * m * m;
    return f0 + (vec3(1.0f) - f0) * m5;
}

// ---- Environment (equirectangular, official implementation §8 convention) ------------------------
// u = atan2(d.x, -d.z) / 2pi + 0.5, v = acos(d.y) / pi, after rotating d by `rotation` about +y.
NB_FN vec2 nb_env_dir_to_uv(vec3 d, float rotation) {
    float c = cos(rotation);
    float s = sin(rotation);
    vec3 r = vec3(c * d.x + s * d.z, d.y, -s * d.x + c * d.z);
    float u = nb_atan2(r.x, -r.z) * (0.5f * NB_INV_PI) + 0.5f;
    float v = acos(clamp(r.y, -1.0f, 1.0f)) * NB_INV_PI;
    return vec2(u - floor(u), v);
}

// Bilinear footprint of (u, v) in a w x h equirectangular map: texel centres at half-integers, u wraps
// (the seam), v clamps (the poles). Texels lo/hi per axis, weights f of the hi ones.
NB_FN void nb_env_bilinear_footprint(vec2 uv, uint w, uint h, NB_OUT(uvec2) lo, NB_OUT(uvec2) hi, NB_OUT(vec2) f) {
    float fx = uv.x * float(w) - 0.5f;
    float fy = uv.y * float(h) - 0.5f;
    float x0f = floor(fx), y0f = floor(fy);
    f = vec2(fx - x0f, fy - y0f);
    int iw = int(w), ih = int(h), xi = int(x0f), yi = int(y0f);
    lo = uvec2(uint(((xi % iw) + iw) % iw), uint(clamp(yi, 0, ih - 1)));
    hi = uvec2(uint((((xi + 1) % iw) + iw) % iw), uint(clamp(yi + 1, 0, ih - 1)));
}

NB_FN vec3 nb_env_uv_to_dir(vec2 uv, float rotation) {
    float phi = (uv.x - 0.5f) * 2.0f * NB_PI;
    float theta = uv.y * NB_PI;
    float st = sin(theta);
    vec3 r = vec3(st * sin(phi), cos(theta), -st * cos(phi));
    float c = cos(rotation);
    float s = sin(rotation);
    // inverse of the rotation in nb_env_dir_to_uv
    return vec3(c * r.x - s * r.z, r.y, s * r.x + c * r.z);
}

#endif
