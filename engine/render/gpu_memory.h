// What a mesh and a neural model occupy on the GPU, computed on the host from the layouts the renderer
// uploads (gpu_scene.cpp, neural_model_gpu.cpp, neural_stage.cpp), so that benchmarks can compare the two
// without a device (issue 11: memory figures count every buffer).
#pragma once
#include <cstdint>
#include <vector>

#include "engine/bvh/mesh_bvh.h"
#include "engine/neural/model_file.h"
#include "engine/scene/scene.h"

namespace nbvh::render {

// A mesh as pack_scene uploads it: every vertex (GpuVertex), the triangles its BLAS keeps (GpuTriangle) and
// the BLAS nodes (GpuWideNode, to_wide_layout). Textures and materials are not counted (both
// representations shade with them). A bounds-only BLAS (bounds_only_mesh_bvh) counts the vertices and every
// triangle of the mesh, no nodes (none were built).
uint64_t mesh_gpu_bytes(const Mesh& mesh, const MeshBvh& blas);
uint64_t mesh_gpu_bytes(const Mesh& mesh); // builds the BLAS with default_blas_options()

// A model as a hybrid render holds it, by buffer. Resident buffers only: the per-ray working buffers of
// the neural stage (pending leaves, ray state: neural_scratch_bytes_per_ray per queue slot) scale with
// the wave size, not with the model.
struct NeuralGpuBytes {
    uint64_t levels = 0, grid = 0, mlp = 0, mlp_transposed = 0; // the transposed copy feeds coopmat kernels
    uint64_t grid_ypair = 0;         // the y-pair copy of the dense levels, for the split gather (neural_grid_pack.h)
    uint64_t nodes = 0;              // N-BVH nodes of every LoD and asset (GpuBvhNode)
    std::vector<uint64_t> lod_nodes; // ... of each LoD alone
    uint64_t node_bounds = 0;        // NB_NBVH_BOUNDS_WORDS per N-BVH node (two 16-byte words)
    uint64_t occupancy = 0;          // NB_OCC_WORDS words per N-BVH node (0: the model has no masks)
    uint64_t materials = 0;          // one word per N-BVH node (0: the model has no node materials)
    uint64_t assets = 0, params = 0; // GpuNeuralAsset table, GpuNeuralParams
    uint64_t total() const {
        return levels + grid + grid_ypair + mlp + mlp_transposed + nodes + node_bounds + occupancy + materials + assets +
               params;
    }
    // A model that keeps only the cut of `lod` (the others' nodes not uploaded).
    uint64_t total_for_lod(uint32_t lod) const;
};
NeuralGpuBytes neural_gpu_bytes(const NeuralModel& model);

// Bytes of the neural stage's per-ray working buffers per queue slot (path and shadow halves) with
// `leaves_per_round` pending leaves per ray.
uint64_t neural_scratch_bytes_per_ray(uint32_t leaves_per_round);

} // namespace nbvh::render
