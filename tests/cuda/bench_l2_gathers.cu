// What bounds the neural query's hash-grid gather on random queries (results/neural/README.md): the rate
// at which the GPU serves loads scattered at random over a table of the hash grid's size, with nothing
// else running. A random query reads 3 points x 8 levels x 8 corners of 8 bytes (4 fp16 features); the
// fused kernels load a corner pair (x, x + 1) as one 16-byte access where it is aligned, 96 accesses
// per query in all (lib/neural_grid.glsl). Each access here is one such load, to an index drawn by a
// 32-bit mix (lowbias32), for tables that fit the L2 cache (the default models' 2^16 and 2^18 entries per
// level, 8 levels) and one that does not:
//   8 B    one 8-byte load per access (a lone corner)
//   16 B   one 16-byte load per access (a corner pair)
// Usage: bench_l2_gathers   (one line per table and width, twice; exits 1 without a GPU).
#include <cstdint>
#include <cstdio>

#include "tests/cuda/bench_timing.cuh"

namespace {

constexpr uint32_t kThreads = 1u << 22, kLoads = 16u; // 64 M accesses per launch

__device__ uint32_t mix(uint32_t e) {
    e ^= e >> 16;
    e *= 0x7feb352du;
    e ^= e >> 15;
    e *= 0x846ca68bu;
    e ^= e >> 16;
    return e;
}

// `words` 16-byte words in the table (a power of two); W = 8 or 16 bytes per access. The sum keeps every load
// live.
template <int W> __global__ void k_gather(const uint4* table, uint32_t words, uint32_t seed, uint32_t* sink) {
    const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    uint32_t acc = 0;
#pragma unroll
    for (uint32_t k = 0; k < kLoads; ++k) {
        const uint32_t e = mix(i * kLoads + k + seed);
        if constexpr (W == 16) {
            const uint4 v = __ldg(table + (e & (words - 1u)));
            acc += v.x ^ v.y ^ v.z ^ v.w;
        } else {
            const uint2 v = __ldg(reinterpret_cast<const uint2*>(table) + (e & (2u * words - 1u)));
            acc += v.x ^ v.y;
        }
    }
    if (acc == 0x12345678u) sink[0] = acc; // practically never: the loads cannot be dropped
}

template <int W> void measure(const char* table_name, const uint4* table, uint32_t words, uint32_t* sink) {
    const uint32_t blocks = kThreads / 256u;
    const double per = nbvh::bench::mean_launch_ms(
        [&](uint32_t seed) { k_gather<W><<<blocks, 256>>>(table, words, seed, sink); });
    const double accesses = double(kThreads) * kLoads;
    std::printf(
        "%-22s %2d B: %.4f ms per %.0f M accesses: %.1f G accesses/s, %.0f GB/s requested; 96 per query: "
        "%.2f G queries/s (%s)\n",
        table_name, W, per, accesses / 1e6, accesses / (per * 1e6), accesses * W / (per * 1e6),
        accesses / (per * 1e6) / 96.0, cudaGetErrorString(cudaGetLastError()));
}

} // namespace

int main() {
    cudaDeviceProp prop{};
    if (cudaGetDeviceProperties(&prop, 0) != cudaSuccess) {
        std::fprintf(stderr, "bench_l2_gathers: no CUDA device\n");
        return 1;
    }
    std::printf("device: %s, L2 %d MiB\n", prop.name, prop.l2CacheSize >> 20);
    struct Table {
        const char* name;
        uint32_t words;
    };
    // 8 levels of 2^T entries of 8 bytes (the coarse levels are smaller; the 2^16 table is the default
    // scene's model's, 2^18 the paper's and the standalone benchmark's), and a table four times the L2.
    const Table tables[] = {{"8 x 2^16 entries (4 MiB)", 8u << 15},
                            {"8 x 2^18 entries (16 MiB)", 8u << 17},
                            {"256 MiB (not L2-resident)", 1u << 24}};
    uint4* table = nullptr;
    uint32_t* sink = nullptr;
    if (cudaMalloc(&table, size_t(1u << 24) * 16) != cudaSuccess || cudaMalloc(&sink, 4) != cudaSuccess) {
        std::fprintf(stderr, "bench_l2_gathers: cudaMalloc failed\n");
        return 1;
    }
    cudaMemset(table, 0x3c, size_t(1u << 24) * 16);
    for (int round = 0; round < 2; ++round)
        for (const Table& t : tables) {
            measure<8>(t.name, table, t.words, sink);
            measure<16>(t.name, table, t.words, sink);
        }
    cudaFree(table);
    cudaFree(sink);
    return 0;
}
