// Kernels of shared_training_kernels.h: one thread per case, the shared functions as the CUDA trainer
// calls them (k_adam, k_mlp), compiled with the trainer's nvcc flags (IEEE division and sqrt, denormals
// kept, FMA contraction on).
#include <cuda_runtime.h>

#include <algorithm>

#include "tests/cuda/shared_training_kernels.h"

namespace nbvh::test {
namespace {

NB_FN void adam_case(AdamCase& c) {
    c.updated = nb_adam_update(c.w, c.m, c.v, c.t, c.g, c.rule, nullptr, nullptr, 0u) ? 1u : 0u;
}

NB_FN void loss_case(LossCase& c) {
    c.total = nb_composite_loss(c.y, c.t, c.cfg, c.value, c.dl_dy);
    for (uint32_t o = 0; o < NB_MLP_OUTPUTS; ++o) c.dl_dz[o] = nb_presigmoid_gradient(c.dl_dy[o], c.y[o]);
}

__global__ void k_cases(AdamCase* adam, uint32_t na, LossCase* loss, uint32_t nl) {
    const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < na) adam_case(adam[i]);
    if (i < nl) loss_case(loss[i]);
}

template <class T>
std::string copy(T* dst, const T* src, size_t n, cudaMemcpyKind kind) {
    const cudaError_t e = cudaMemcpy(dst, src, n * sizeof(T), kind);
    return e == cudaSuccess ? std::string() : std::string(cudaGetErrorString(e));
}

} // namespace

void apply_on_host(std::vector<AdamCase>& adam, std::vector<LossCase>& loss) {
    for (AdamCase& c : adam) adam_case(c);
    for (LossCase& c : loss) loss_case(c);
}

std::string apply_on_device(std::vector<AdamCase>& adam, std::vector<LossCase>& loss) {
    AdamCase* da = nullptr;
    LossCase* dl = nullptr;
    std::string err;
    const size_t na = std::max<size_t>(adam.size(), 1), nl = std::max<size_t>(loss.size(), 1);
    if (cudaMalloc(&da, na * sizeof(AdamCase)) != cudaSuccess || cudaMalloc(&dl, nl * sizeof(LossCase)) != cudaSuccess) {
        err = "cudaMalloc failed";
    }
    if (err.empty()) err = copy(da, adam.data(), adam.size(), cudaMemcpyHostToDevice);
    if (err.empty()) err = copy(dl, loss.data(), loss.size(), cudaMemcpyHostToDevice);
    if (err.empty()) {
        const uint32_t n = uint32_t(std::max(adam.size(), loss.size()));
        k_cases<<<(n + 63) / 64, 64>>>(da, uint32_t(adam.size()), dl, uint32_t(loss.size()));
        const cudaError_t e = cudaDeviceSynchronize();
        if (e != cudaSuccess) err = cudaGetErrorString(e);
    }
    if (err.empty()) err = copy(adam.data(), da, adam.size(), cudaMemcpyDeviceToHost);
    if (err.empty()) err = copy(loss.data(), dl, loss.size(), cudaMemcpyDeviceToHost);
    cudaFree(da);
    cudaFree(dl);
    return err;
}

} // namespace nbvh::test
