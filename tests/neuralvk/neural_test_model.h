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

// Random rays through random sub-boxes (leaves) of the asset box `lo`..`hi`; a quarter start inside
// their leaf (reversed queries).
std::vector<GpuNeuralQuery> random_queries(uint64_t seed, size_t n, glm::vec3 lo, glm::vec3 hi);

// A GPU kernel's hits against the CPU oracle. Differences are measured, not asserted: the caller
// checks them against its kernel's bounds (see neural_crosscheck_test.cpp for why they are what they
// are). Visibility decisions are compared only where the reference lies `vis_margin` or more away
// from the threshold, acceptance only where the reference hit is that far from the acceptance edge.
struct CrossCheck {
    float max_out = 0.0f;        // max |y_gpu - y_ref| over visibility, depth, albedo
    float max_t = 0.0f;          // max |t_gpu - t_ref| / (segment length + pad)
    float max_n = 0.0f;          // max |n_gpu - n_ref| where the reference normal is well defined
    int decisions = 0;           // visibility decisions compared
    int decision_errors = 0;     // of those, different
    int acceptance_errors = 0;   // depth acceptance different away from its edge
    int near_threshold = 0;
    int visible = 0;
    int reversed = 0;
    int non_finite = 0;
};
CrossCheck cross_check(const TestModel& m, const std::vector<GpuNeuralQuery>& qs,
                       const std::vector<GpuNeuralHit>& hits, float vis_margin);

// Hits of `b` that differ bitwise from those of `a` at the same index (b no longer than a).
size_t differing_hits(const std::vector<GpuNeuralHit>& a, const std::vector<GpuNeuralHit>& b);

} // namespace nbvh::test
