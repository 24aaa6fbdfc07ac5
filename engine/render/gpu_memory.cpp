#include "engine/render/gpu_memory.h"

#include <algorithm>

#include "engine/bvh/wide_bvh.h"
#include "engine/render/neural_grid_pack.h"
#include "engine/render/neural_model_gpu.h"
#include "shaders/shared/neural_gpu.h"
#include "shaders/shared/scene_gpu.h"
#include "shaders/shared/wavefront_gpu.h"

namespace nbvh::render {

uint64_t mesh_gpu_bytes(const Mesh& mesh, const MeshBvh& blas) {
    const uint64_t vertices = uint64_t(mesh.positions.size()) * sizeof(GpuVertex);
    if (blas.bounds_only)
        return vertices + uint64_t(mesh.triangle_count()) * sizeof(GpuTriangle); // no nodes built
    return vertices + uint64_t(blas.triangle_count()) * sizeof(GpuTriangle) +
           uint64_t(to_wide_layout(blas.bvh).size()) * sizeof(GpuWideNode);
}

uint64_t mesh_gpu_bytes(const Mesh& mesh) { return mesh_gpu_bytes(mesh, build_mesh_bvh(mesh)); }

uint64_t NeuralGpuBytes::total_for_lod(uint32_t lod) const {
    if (lod_nodes.empty()) return total();
    return total() - nodes + lod_nodes[std::min<size_t>(lod, lod_nodes.size() - 1)];
}

NeuralGpuBytes neural_gpu_bytes(const NeuralModel& model) {
    NeuralGpuBytes b;
    auto packed = [](size_t halves) { return uint64_t((halves + 1) / 2) * sizeof(uint32_t); }; // pack_halves
    b.levels = uint64_t(model.levels.size() + 1) * sizeof(uvec4); // packed (hashgrid.h nb_level_pack) + y-pair word
    // The grid buffer (neural_grid_pack.h): the entries, and the y-pair table apart. Without a device the
    // table is taken whole (a device whose storage-buffer bindings are smaller gets less of it).
    const GridLayout grid = grid_layout(model);
    b.grid = grid.entry_bytes;
    b.grid_ypair = grid.ypair_bytes;
    b.mlp = packed(model.mlp.size());
    b.mlp_transposed = b.mlp;
    std::vector<GpuBvhNode> nodes;
    std::vector<uint32_t> roots;
    pack_lod_nodes(model, nodes, roots);
    b.nodes = uint64_t(nodes.size()) * sizeof(GpuBvhNode);
    // pack_lod_nodes concatenates LoD by LoD: the LoD's first root to the next LoD's first root.
    const size_t assets = std::max<size_t>(1, model.assets.size());
    for (size_t l = 0; l * assets < roots.size(); ++l) {
        const uint64_t first = roots[l * assets];
        const uint64_t end = (l + 1) * assets < roots.size() ? roots[(l + 1) * assets] : nodes.size();
        b.lod_nodes.push_back((end - first) * sizeof(GpuBvhNode));
    }
    b.node_bounds = uint64_t(model.nodes.size()) * NB_NBVH_BOUNDS_WORDS * sizeof(uint32_t);
    b.occupancy = uint64_t(model.occupancy.size()) * sizeof(uint32_t); // after the bounds, same buffer
    b.materials = uint64_t(model.node_materials.size() + model.material_fits.size()) * sizeof(uint32_t); // after the masks, same buffer
    b.assets = uint64_t(model.assets.size()) * sizeof(GpuNeuralAsset);
    b.params = sizeof(GpuNeuralParams);
    return b;
}

uint64_t neural_scratch_bytes_per_ray(uint32_t leaves_per_round) {
    // neural_stage.cpp install(): two halves of leaves_per_round pending leaves per ray, and a ray state for
    // the path ray and one for the shadow ray of each slot.
    return 2ull * leaves_per_round * sizeof(GpuPendingLeaf) + 2ull * sizeof(GpuNeuralRayState);
}

} // namespace nbvh::render
