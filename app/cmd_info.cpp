// nbvh info MODEL: what a .nbvh model holds — hyperparameters, the N-BVH per level of detail, memory of
// the neural part (every GPU buffer a hybrid render holds) against the triangles it replaces, and how it
// was trained.
#include <cstdio>
#include <ctime>
#include <string>
#include <utility>
#include <vector>

#include "app/commands.h"
#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/neural/model_file.h"
#include "engine/render/gpu_memory.h"

namespace nbvh::app {

namespace {

std::string human_bytes(double b) {
    const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB"};
    int u = 0;
    while (b >= 1024.0 && u < 4) { b /= 1024.0; ++u; }
    return u == 0 ? strfmt("%.0f B", b) : strfmt("%.2f %s", b, units[u]);
}

std::string utc_date(int64_t unix_seconds) {
    if (unix_seconds <= 0) return "unknown";
    const std::time_t t = std::time_t(unix_seconds);
    std::tm tm{};
    if (!gmtime_r(&t, &tm)) return "unknown";
    char buf[64];
    std::strftime(buf, sizeof(buf), "%Y-%m-%d %H:%M:%S UTC", &tm);
    return buf;
}

uint64_t classical_bytes(const TrainingMetadata& m) { return mesh_and_blas_bytes(m.source_triangles, m.source_vertices); }

// N-BVH nodes and leaves of the subtree under `root` (the finest cut; load_model checked the indices:
// children follow their parent).
std::pair<uint32_t, uint32_t> subtree_size(const NeuralModel& m, uint32_t root) {
    uint32_t nodes = 0, leaves = 0;
    std::vector<uint32_t> stack{root};
    while (!stack.empty() && nodes < m.nodes.size()) {
        const uint32_t i = stack.back();
        stack.pop_back();
        nodes++;
        if (!m.nodes[i].has_children()) leaves++;
        else stack.insert(stack.end(), {m.nodes[i].left, m.nodes[i].left + 1});
    }
    return {nodes, leaves};
}

void print_model(const std::string& path) {
    const NeuralModel m = load_model(path);
    const NbvhTree tree = m.tree();
    const NeuralConfig& c = m.cfg;
    std::printf("model        %s (format version %u)\n", path.c_str(), m.file_version);
    std::printf("assets       %zu (each its own N-BVH subtree, one shared network)\n", m.assets.size());
    for (const ModelAsset& as : m.assets) {
        const auto [nodes, leaves] = subtree_size(m, as.root);
        std::printf("  %-28s %8u triangles  %5u N-BVH nodes (%u leaves)  %zu scene node%s  root %u  scale %g%s\n",
                    as.name.c_str(), as.triangles, nodes, leaves, as.node_paths.size(),
                    as.node_paths.size() == 1 ? "" : "s", as.root, double(as.scale),
                    as.geometry_hash ? "" : "  (no fingerprint: format version 1)");
    }
    std::printf("encoding box (%g, %g, %g) - (%g, %g, %g)\n", m.encoding_box.lo.x, m.encoding_box.lo.y,
                m.encoding_box.lo.z, m.encoding_box.hi.x, m.encoding_box.hi.y, m.encoding_box.hi.z);
    std::printf("hash grid    %u levels x %u features, base resolution %u, per-level scale %g, 2^%u entries per "
                "hashed level\n", c.grid_levels, c.grid_features, c.base_resolution, double(c.per_level_scale),
                c.log2_hash_size);
    for (size_t l = 0; l < m.levels.size(); ++l)
        std::printf("  level %zu    resolution %5u  %8u entries  %s\n", l, m.levels[l].resolution, m.levels[l].size,
                    m.levels[l].hashed ? "hashed" : "dense");
    std::printf("mlp          %u -> %u x %u hidden -> %u outputs, %zu fp16 weights\n",
                c.segment_points * c.grid_levels * c.grid_features, c.mlp_width, c.mlp_hidden_layers, c.mlp_outputs,
                m.mlp.size());
    std::printf("n-bvh        %u nodes, %u leaves, depth %u, %u level%s of detail\n", tree.node_count(),
                tree.leaf_count(), tree.max_depth(), m.lod_count, m.lod_count == 1 ? "" : "s");
    for (uint32_t l = 0; l < m.lod_count; ++l) {
        const uint32_t n = m.lod_node_counts[l];
        std::printf("  LoD %u      %8u nodes  %8u leaves%s\n", l, n, (n + 1) / 2,
                    l == 0 ? "  (finest)" : (l + 1 == m.lod_count ? "  (coarsest)" : ""));
    }
    // Every GPU buffer a hybrid render holds for the model (engine/render/gpu_memory.h).
    const render::NeuralGpuBytes b = render::neural_gpu_bytes(m);
    const uint64_t neural = b.total();
    std::printf("memory       %s on the GPU (grid %s + its y-pair copy %s, mlp %s + its transposed copy, nodes of %zu LoD(s) %s + bounds "
                "%s, occupancy masks %s, node materials %s, level table %s, asset table %s); with LoD 0 alone %s\n",
                human_bytes(double(neural)).c_str(), human_bytes(double(b.grid)).c_str(),
                human_bytes(double(b.grid_ypair)).c_str(), human_bytes(double(b.mlp)).c_str(), b.lod_nodes.size(), human_bytes(double(b.nodes)).c_str(),
                human_bytes(double(b.node_bounds)).c_str(),
                b.occupancy ? human_bytes(double(b.occupancy)).c_str() : "none (model before format version 3)",
                b.materials ? (human_bytes(double(b.materials)) + (m.material_fits.empty() ? " (means; fits from format version 5)"
                                                                                           : " (means and fits)")).c_str()
                            : "none (model before format version 4)",
                human_bytes(double(b.levels)).c_str(),
                human_bytes(double(b.assets)).c_str(), human_bytes(double(b.total_for_lod(0))).c_str());
    if (m.meta.source_triangles > 0) {
        const uint64_t classic = classical_bytes(m.meta);
        std::printf("replaces     %llu triangles, %llu vertices: ~%s as mesh + BLAS -> compression %.1fx\n",
                    (unsigned long long)m.meta.source_triangles, (unsigned long long)m.meta.source_vertices,
                    human_bytes(double(classic)).c_str(), double(classic) / double(neural));
    } else {
        std::printf("replaces     unknown (the model does not record its source mesh size)\n");
    }
    const TrainingMetadata& t = m.meta;
    std::printf("training     %llu steps, batch %u, final loss %g, %.1f s on %s\n", (unsigned long long)t.steps,
                t.batch_size, double(t.final_loss), t.seconds, t.backend.empty() ? "?" : t.backend.c_str());
    std::printf("split        interval %u, last split %u, start %u, scaling %g, interval scaling %g\n",
                t.splitting_interval, t.last_split_iteration, t.start_split_num, double(t.split_scaling),
                double(t.split_interval_scaling));
    std::printf("source       %s (fnv1a64 %016llx)\n", t.source.empty() ? "?" : t.source.c_str(),
                (unsigned long long)t.source_hash);
    std::printf("created      %s\n", utc_date(t.created_unix).c_str());
}

} // namespace

void add_info_command(CLI::App& app) {
    auto* cmd = app.add_subcommand("info", "Print a .nbvh model: sizes, nodes per LoD, memory vs the mesh it "
                                           "replaces, training metadata");
    auto path = std::make_shared<std::string>();
    cmd->add_option("model", *path, "model file (.nbvh)")->required();
    cmd->callback([path] { print_model(*path); });
}

} // namespace nbvh::app
