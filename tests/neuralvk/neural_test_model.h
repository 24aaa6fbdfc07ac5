// A small random network with varied outputs for the GPU/CPU cross-checks: tcnn initialisation, then
// grid features spread to +-1 (trained grids have O(0.1..1) features; the tcnn init of +-1e-4 would put
// every output at 0.5, right on the visibility threshold). Weights are rounded to fp16 in the fp32
// master copy too, so the CPU reference and the GPU see the same values.
#pragma once
#include "engine/neural/model_file.h"
#include "engine/neural/reference_network.h"
#include "shaders/shared/neural_gpu.h"

#include <random>
#include <vector>

namespace nbvh::test {

struct TestModel {
    NeuralModel model;               // what the GPU gets (fp16, one root leaf)
    neural::NetworkWeights weights;  // what the CPU reference gets (same values, as floats)
    GpuEncodingBox box;
};

// `lo`..`hi`: the asset box; log2_hash small keeps the test fast.
TestModel make_test_model(uint64_t seed, glm::vec3 lo = glm::vec3(-1.0f), glm::vec3 hi = glm::vec3(1.0f),
                          uint32_t log2_hash = 14, float grid_amplitude = 1.0f, float mlp_gain = 1.5f);

// CPU oracle: fp16-emulated forward of the same query (segment points from the shared header).
neural::Outputs reference_outputs(const TestModel& m, const GpuNeuralQuery& q);

} // namespace nbvh::test
