// Kernel of clip_box_kernels.h: one thread per case, inv_dir + clip_dilated (and clip_regular where it
// applies) exactly as k_sample's first-leaf search calls them (on a box's centre and half extent, from
// box_centre_half as the cut tree stores them). Compiled with --fmad=false like sampling_kernels.cu
// (tests/cuda/CMakeLists.txt).
#include "tests/cuda/clip_box_kernels.h"
#include "trainer/cuda/clip_box.cuh"
#include "trainer/cuda/cut_tree.h"

namespace nbvh::test {
namespace {

__global__ void k_clip(ClipCase* cases, const float* boxes, const uint8_t* regular_box, uint32_t n) {
    const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n) return;
    ClipCase& c = cases[i];
    const vec3 o(c.origin[0], c.origin[1], c.origin[2]), d(c.dir[0], c.dir[1], c.dir[2]);
    const cuda::InvDir id = cuda::inv_dir(d);
    float t0 = 0.0f, t1 = 0.0f;
    const float* b = boxes + 6 * size_t(i);
    const float centre[3] = {b[0], b[1], b[2]}, half[3] = {b[3], b[4], b[5]}; // as a cut node holds it
    c.hit = cuda::clip_dilated(centre, half, o, d, id, c.dilation, t0, t1) ? 1u : 0u;
    c.t_entry = c.hit ? t0 : 0.0f;
    c.t_exit = c.hit ? t1 : 0.0f;
    c.regular = regular_box[i] && cuda::slab_ray_regular(d) ? 1u : 0u;
    float r0 = 0.0f, r1 = 0.0f;
    c.hit_regular =
        c.regular && cuda::clip_regular(centre, half, cuda::slab_ray(o, d, id, c.dilation), r0, r1) ? 1u : 0u;
    c.t_entry_regular = c.hit_regular ? r0 : 0.0f;
    c.t_exit_regular = c.hit_regular ? r1 : 0.0f;
}

std::string error_of(cudaError_t e) { return e == cudaSuccess ? std::string() : std::string(cudaGetErrorString(e)); }

} // namespace

std::string clip_on_device(std::vector<ClipCase>& cases) {
    const uint32_t n = uint32_t(cases.size());
    std::vector<float> boxes(6 * size_t(n));
    std::vector<uint8_t> regular(n);
    for (uint32_t i = 0; i < n; ++i) { // each box as the cut tree stores it (cut_tree.h)
        float* b = &boxes[6 * size_t(i)];
        cuda::box_centre_half(cases[i].box, cases[i].box + 3, b, b + 3);
        regular[i] = cuda::classify_cut_box(b, b + 3) == cuda::CutBox::regular ? 1 : 0;
    }
    ClipCase* dc = nullptr;
    float* db = nullptr;
    uint8_t* dr = nullptr;
    std::string err = error_of(cudaMalloc(&dc, n * sizeof(ClipCase)));
    if (err.empty()) err = error_of(cudaMalloc(&db, boxes.size() * sizeof(float)));
    if (err.empty()) err = error_of(cudaMalloc(&dr, n));
    if (err.empty()) err = error_of(cudaMemcpy(dr, regular.data(), n, cudaMemcpyHostToDevice));
    if (err.empty()) err = error_of(cudaMemcpy(dc, cases.data(), n * sizeof(ClipCase), cudaMemcpyHostToDevice));
    if (err.empty()) err = error_of(cudaMemcpy(db, boxes.data(), boxes.size() * sizeof(float), cudaMemcpyHostToDevice));
    if (err.empty()) {
        k_clip<<<(n + 127) / 128, 128>>>(dc, db, dr, n);
        err = error_of(cudaGetLastError());
    }
    if (err.empty()) err = error_of(cudaMemcpy(cases.data(), dc, n * sizeof(ClipCase), cudaMemcpyDeviceToHost));
    cudaFree(dc);
    cudaFree(db);
    cudaFree(dr);
    return err;
}

} // namespace nbvh::test
