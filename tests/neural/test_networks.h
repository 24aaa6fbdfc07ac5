// Networks for the neural tests: a small (T = 14) network whose grid values and weights are large enough
// that every layer and the grid matter (tcnn's +-1e-4 grid init would make later layers' grid gradients
// vanish in comparisons against finite differences or the per-sample reference).
#pragma once
#include <cstdint>
#include <random>

#include "engine/neural/reference_network.h"

namespace nbvh::neural::test {

inline NetworkWeights large_value_network(uint64_t seed) {
    NeuralConfig cfg;
    cfg.log2_hash_size = 14;
    NetworkWeights w = create_network(cfg, seed);
    std::mt19937 rng(uint32_t(seed) + 7u);
    std::uniform_real_distribution<float> u(-0.5f, 0.5f);
    for (float& v : w.grid) v = u(rng);
    for (float& v : w.mlp) v *= 1.5f;
    return w;
}

} // namespace nbvh::neural::test
