// The random numbers of one path segment (camera_rays.comp, shade.comp). Each decision of a segment
// has its own 2D dimension pair (NB_PAIR_*), so with --sampler sobol (params.path_sampler ==
// NB_SAMPLER_SOBOL, the default) every pair is an Owen-scrambled Sobol net over the pixel's samples
// (shared/sampling.h nb_qmc_2d), seeded by pixel, --seed, segment and pair: nothing is carried between
// segments. --sampler random draws the same decisions from the path's PCG state (NB_RAY_RNG), as
// before the Sobol sampler. Either way NB_RAY_RNG advances once per segment: it seeds stochastic alpha.
#ifndef NB_PATH_SAMPLER_GLSL
#define NB_PATH_SAMPLER_GLSL
#include "lib/bindings.glsl"
#include "shared/sampling.h"

#define NB_PAIR_CAMERA 0u      // segment 0: pixel jitter (x, y)
#define NB_PAIR_LIGHT_PICK 1u  // y: which light of the strategy (x: unused; the strategy is NB_PAIR_LIGHT's x)
#define NB_PAIR_LIGHT 2u       // the strategy (x, rescaled), then the point or direction on the light
#define NB_PAIR_LOBE 3u        // x: BSDF lobe, y: Russian roulette
#define NB_PAIR_BSDF 4u        // the BSDF direction
#define NB_PAIR_MATERIAL 5u    // x: the neural surface's material spread sign

struct PathSampler {
    uint rng;         // PCG state (--sampler random), NB_RAY_RNG
    uint pixel_seed;  // nb_qmc_pixel_seed
    uint sample_index;
    uint depth;
};

// The sampler of the path in wave slot `slot` at segment `depth`, PCG state `rng` (NB_RAY_RNG).
PathSampler nb_path_sampler(uint slot, uint depth, uint rng) {
    PathSampler ps;
    ps.rng = rng;
    ps.pixel_seed = nb_qmc_pixel_seed(nb_slot_pixel(slot, pc.pixel_offset, pc.wave_samples), params.seed);
    ps.sample_index = nb_slot_sample(slot, pc.sample_index, pc.wave_samples);
    ps.depth = depth;
    return ps;
}

// A camera ray's sampler: segment 0, its PCG state started from pixel, sample and --seed.
PathSampler nb_camera_path_sampler(uint slot, uint pixel) {
    PathSampler ps = nb_path_sampler(slot, 0u, 0u);
    ps.rng = nb_rng_init(pixel, ps.sample_index, params.seed);
    return ps;
}

// The Sobol point of one pair of the path's segment.
vec2 nb_path_sobol(PathSampler ps, uint pair) {
    return nb_qmc_2d(ps.sample_index, nb_qmc_dim_seed(ps.pixel_seed, ps.depth, pair));
}

vec2 nb_path_2d(inout PathSampler ps, uint pair) {
    if (params.path_sampler == NB_SAMPLER_SOBOL) return nb_path_sobol(ps, pair);
    float u1 = nb_rng_next(ps.rng);
    float u2 = nb_rng_next(ps.rng);
    return vec2(u1, u2);
}

// One random bit for a decision only some renders of a seed make (a neural hit's material spread):
// under --sampler random it must not advance the PCG stream, so that a hybrid render and its classical
// reference of the same seed keep sharing their numbers (nbvh bench's shared-seed FLIP); a Sobol pair
// is fixed per decision anyway.
uint nb_path_bit(PathSampler ps, uint pair) {
    if (params.path_sampler == NB_SAMPLER_SOBOL) return nb_path_sobol(ps, pair).x < 0.5f ? 0u : 1u;
    return nb_pcg_hash(ps.rng ^ 0xA511E9B3u) & 1u;
}

// NB_RAY_RNG for the path's next segment.
uint nb_path_next_rng(PathSampler ps) { return nb_pcg_hash(ps.rng ^ 0x2545F491u); }

#endif
