// What bounds the CUDA trainer's grid backward on its fine levels (results/cuda_training.md): the
// throughput of global reductions scattered at random over a table the size of those levels' gradients
// (2^21 entries of 4 features, 32 MiB in fp32), one reduction per corner, 8 corners per item, as many
// items as a step has (2^18 samples x 3 points x 6 fine levels), for each way of adding 4 features:
//   f32x4      one 16-byte vector reduction (sm_90 atomicAdd(float4*), the trainer's)
//   f16x2.v2   one 8-byte vector reduction of fp16 pairs (red.global.add.noftz.v2.f16x2)
//   half2 x2   two 4-byte fp16-pair atomics (tiny-cuda-nn's way)
//   f32x2 x2   two 8-byte vector reductions
// Usage: bench_l2_reductions   (prints one line per variant, twice; exits 1 without a GPU).
#include <cuda_fp16.h>

#include <cstdint>
#include <cstdio>

#include "tests/cuda/bench_timing.cuh"

namespace {

constexpr uint32_t kEntries = 1u << 21, kItems = (1u << 18) * 3u * 6u, kCorners = 8u;

enum class Way { f32x4, f16x2_v2, half2_x2, f32x2_x2 };

// Vector reductions need sm_90; other architectures compile an empty kernel (main refuses them).
template <Way W> __global__ void k_scatter(float* grad, uint32_t seed) {
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ >= 900
    const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= kItems) return;
    const float w = 1e-3f * float(i & 7u);
    for (uint32_t c = 0; c < kCorners; ++c) {
        uint32_t e = i * kCorners + c + seed; // the corner's entry: a 32-bit mix (lowbias32)
        e ^= e >> 16;
        e *= 0x7feb352du;
        e ^= e >> 15;
        e *= 0x846ca68bu;
        e ^= e >> 16;
        e &= kEntries - 1u;
        if constexpr (W == Way::f32x4) {
            atomicAdd(reinterpret_cast<float4*>(grad) + e, make_float4(w, w, w, w));
        } else if constexpr (W == Way::f32x2_x2) {
            atomicAdd(reinterpret_cast<float2*>(grad) + 2 * e, make_float2(w, w));
            atomicAdd(reinterpret_cast<float2*>(grad) + 2 * e + 1, make_float2(w, w));
        } else {
            const __half2 h = __floats2half2_rn(w, w);
            __half2* g = reinterpret_cast<__half2*>(grad) + 2 * size_t(e); // fp16 table: 8 bytes an entry
            if constexpr (W == Way::half2_x2) {
                atomicAdd(g, h);
                atomicAdd(g + 1, h);
            } else {
                const uint32_t u = *reinterpret_cast<const uint32_t*>(&h);
                asm volatile("red.global.add.noftz.v2.f16x2 [%0], {%1, %2};" ::"l"(g), "r"(u), "r"(u)
                             : "memory");
            }
        }
    }
#else
    (void)grad;
    (void)seed;
#endif
}

template <Way W> void measure(const char* name, float* grad) {
    const uint32_t blocks = (kItems + 255u) / 256u;
    const double per = nbvh::bench::mean_launch_ms([&](uint32_t seed) { k_scatter<W><<<blocks, 256>>>(grad, seed); });
    std::printf("%-9s %.4f ms per %u items x %u corners: %.1f G reductions/s (%s)\n", name, per, kItems,
                kCorners, double(kItems) * kCorners / (per * 1e6), cudaGetErrorString(cudaGetLastError()));
}

} // namespace

int main() {
    cudaDeviceProp prop{};
    if (cudaGetDeviceProperties(&prop, 0) != cudaSuccess) {
        std::fprintf(stderr, "bench_l2_reductions: no CUDA device\n");
        return 1;
    }
    if (prop.major < 9) {
        std::fprintf(stderr, "bench_l2_reductions: needs sm_90 (vector reductions), found sm_%d%d\n",
                     prop.major, prop.minor);
        return 1;
    }
    std::printf("device: %s\n", prop.name);
    float* grad = nullptr;
    if (cudaMalloc(&grad, size_t(kEntries) * 16) != cudaSuccess) {
        std::fprintf(stderr, "bench_l2_reductions: cudaMalloc failed\n");
        return 1;
    }
    for (int round = 0; round < 2; ++round) {
        measure<Way::f32x4>("f32x4", grad);
        measure<Way::f16x2_v2>("f16x2.v2", grad);
        measure<Way::half2_x2>("half2 x2", grad);
        measure<Way::f32x2_x2>("f32x2 x2", grad);
    }
    cudaFree(grad);
    return 0;
}
