// Timing of the L2 micro-benchmarks (bench_l2_reductions.cu, bench_l2_gathers.cu): `launch(seed)`
// enqueues one launch on the default stream; 3 warm-up launches (seeds 0-2), then the mean of 20
// (seeds 100-119) between two events, in ms.
#pragma once
#include <cuda_runtime.h>

#include <cstdint>

namespace nbvh::bench {

template <class Launch> double mean_launch_ms(Launch launch) {
    cudaEvent_t a, b;
    cudaEventCreate(&a);
    cudaEventCreate(&b);
    for (uint32_t s = 0; s < 3; ++s) launch(s);
    constexpr int kReps = 20;
    cudaEventRecord(a);
    for (int r = 0; r < kReps; ++r) launch(100u + uint32_t(r));
    cudaEventRecord(b);
    cudaEventSynchronize(b);
    float ms = 0.0f;
    cudaEventElapsedTime(&ms, a, b);
    cudaEventDestroy(a);
    cudaEventDestroy(b);
    return double(ms) / kReps;
}

} // namespace nbvh::bench
