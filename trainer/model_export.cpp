#include "trainer/model_export.h"

#include <chrono>
#include <ctime>

#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/neural/asset_table.h"
#include "engine/neural/node_materials.h"
#include "engine/neural/occupancy.h"

namespace nbvh {

NeuralModel make_neural_model(const TrainingAsset& asset, const TrainResult& result, const TrainOptions& options,
                              const std::string& source, uint64_t source_hash, bool occupancy_masks) {
    NBVH_CHECK(result.tree.frozen());
    NeuralModel m;
    m.cfg = result.weights.cfg;
    m.levels = result.weights.levels;
    m.encoding_box = asset.bounds; // the renderer rebuilds GpuEncodingBox with nb_make_encoding_box
    set_tree(m, result.tree);
    // The asset table: each part's description and the N-BVH node of its subtree root.
    std::vector<uint32_t> node_of_base(asset.bvh().nodes.size(), NBVH_NO_CHILD);
    for (uint32_t i = 0; i < m.nodes.size(); ++i)
        if (m.nodes[i].base_node < node_of_base.size()) node_of_base[m.nodes[i].base_node] = i;
    for (const TrainingPart& p : asset.parts) {
        ModelAsset a = describe_asset(*asset.scene, p.mesh_index);
        a.root = node_of_base[p.root];
        NBVH_CHECK(a.root != NBVH_NO_CHILD);
        a.scale = p.scale;
        a.offset = p.offset;
        m.assets.push_back(std::move(a));
    }
    m.mlp = neural::mlp_to_fp16(result.weights);
    m.grid = neural::grid_to_fp16(result.weights);
    if (occupancy_masks && asset.mesh) { // node boxes and mesh: atlas space
        const auto t0 = std::chrono::steady_clock::now();
        m.occupancy = build_occupancy(m.nodes, *asset.mesh);
        log_info("occupancy masks: %.0f ms, %.1f %% of the LoD-0 leaves' cells occupied (%zu KiB)",
                 std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count(),
                 100.0 * occupancy_fraction(m.tree(), m.occupancy, 0), m.occupancy.size() * 4 / 1024);
    }
    if (asset.mesh && asset.scene) {
        const auto t0 = std::chrono::steady_clock::now();
        NodeMaterialTables t = build_node_materials(m.nodes, asset.bvh(), *asset.mesh, *asset.scene);
        m.node_materials = std::move(t.means);
        m.material_fits = std::move(t.fits);
        log_info("node materials: %.0f ms (means and fits, %zu KiB)",
                 std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count(),
                 (m.node_materials.size() + m.material_fits.size()) * 4 / 1024);
    }
    TrainingMetadata& meta = m.meta;
    meta.steps = result.log.size();
    meta.final_loss = result.log.empty() ? 0.0f : float(result.log.back().loss.total);
    meta.seconds = result.seconds;
    meta.batch_size = options.batch_size;
    meta.backend = result.backend;
    meta.source = source;
    meta.source_hash = source_hash;
    meta.source_triangles = asset.triangle_count();
    meta.source_vertices = asset.mesh ? asset.mesh->positions.size() : 0;
    meta.created_unix = int64_t(std::time(nullptr));
    const SplitSchedule s = make_split_schedule(options);
    meta.splitting_interval = s.splitting_interval;
    meta.last_split_iteration = s.last_split_iteration;
    meta.start_split_num = s.start_split_num;
    meta.split_scaling = s.split_scaling;
    meta.split_interval_scaling = s.split_interval_scaling;
    return m;
}

} // namespace nbvh
