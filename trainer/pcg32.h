// PCG32 (O'Neill) and the random streams of training samples, one definition for the CPU backend
// (trainer/cpu) and the CUDA kernels (trainer/cuda/sampling_kernels.cu): both draw the same rays for a
// seed. No glm here: nvcc compiles this header too.
#pragma once
#include <cstdint>

#ifndef NBVH_HOST_DEVICE
#if defined(__CUDACC__)
#define NBVH_HOST_DEVICE __host__ __device__
#else
#define NBVH_HOST_DEVICE
#endif
#endif

namespace nbvh {

// Small, fast, and splittable by stream id, so each (step, slot, attempt) draws an independent sequence
// and a run is reproducible from its seed whatever the thread count or GPU.
class Pcg32 {
public:
    NBVH_HOST_DEVICE Pcg32(uint64_t seed, uint64_t stream) {
        inc_ = (stream << 1u) | 1u;
        next_u32();
        state_ += seed;
        next_u32();
    }
    NBVH_HOST_DEVICE uint32_t next_u32() {
        const uint64_t old = state_;
        state_ = old * 6364136223846793005ull + inc_;
        const uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
        const uint32_t rot = uint32_t(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
    }
    // Uniform in [0, 1): 24 random bits, so 1.0f is never returned.
    NBVH_HOST_DEVICE float next_float() { return float(next_u32() >> 8) * (1.0f / 16777216.0f); }

private:
    uint64_t state_ = 0, inc_ = 0;
};

// SplitMix64's finaliser (Steele et al. 2014): a bijective 64-bit mix, every input bit reaching every output bit.
NBVH_HOST_DEVICE inline uint64_t mix64(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

// Where a training sample's random numbers come from. Slot `slot` of step `step` tries rays until one
// is kept (misses and the survival roulette's rejections are redrawn); its attempt k draws from
// attempt_rng(k). Every attempt has its own stream, so attempts can run in any order or in parallel (the
// CUDA sampler spreads one slot's attempts over idle lanes of its warp) and the sample is still the first
// kept attempt. The start state is a hash of (seed, step, attempt, slot): seeds that differ by a
// multiple of a constant (seed ^ k * C) gave measurably correlated neighbouring attempts (|r| up to 0.07
// over 40,000 slots, tests/trainer/sample_streams_test.cpp), and PCG streams that share a start state
// and differ only in their increment are related too. (Until 2026-11: one stream per slot, attempts in
// sequence.)
// Attempts a slot makes before it gives up (leaf -1, not trained), so a cut that rays cannot reach never
// hangs training. Both backends stop at the same attempt.
inline constexpr uint32_t kMaxSampleAttempts = 100000u;

struct SampleSlot {
    uint64_t seed = 0;
    uint32_t step = 0;
    uint32_t slot = 0;

    NBVH_HOST_DEVICE uint64_t attempt_seed(uint32_t attempt) const {
        return mix64(seed ^ mix64(((uint64_t(step) << 32) | attempt) ^ mix64(0x9E3779B97F4A7C15ull + slot)));
    }
    NBVH_HOST_DEVICE Pcg32 attempt_rng(uint32_t attempt) const { return Pcg32(attempt_seed(attempt), slot); }
    // Random bits of triangle `tri`'s stochastic alpha coverage (glTF BLEND, nb_alpha_covers) in this
    // sample's ground truth: independent per seed, step, slot and triangle (original index), the same
    // on the CPU and CUDA backends.
    NBVH_HOST_DEVICE uint32_t coverage_bits(uint32_t tri) const {
        return uint32_t(mix64(seed ^ mix64(((uint64_t(step) << 32) | tri) ^ mix64(0xC2B2AE3D27D4EB4Full + slot))) >> 32);
    }
};

} // namespace nbvh
