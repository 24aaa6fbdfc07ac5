#include "engine/neural/node_materials.h"

#include "engine/neural/asset_table.h"
#include "shaders/shared/neural_gpu.h"

namespace nbvh {

namespace {

// Sums over every base-BVH node's subtree, children before parents (iterative post-order).
std::vector<MaterialSums> subtree_sums(const Bvh& base, const Mesh& mesh, const Scene& scene) {
    std::vector<MaterialSums> sums(base.nodes.size());
    Material fallback; // an out-of-range material: asset_shading's defaults
    fallback.metallic = 0.0f;
    auto add = [](MaterialSums& a, const MaterialSums& b) {
        a.area += b.area;
        a.metallic += b.metallic;
        a.roughness += b.roughness;
    };
    std::vector<std::pair<uint32_t, bool>> stack{{0u, false}};
    while (!stack.empty()) {
        const auto [i, children_done] = stack.back();
        stack.pop_back();
        const BvhNode& n = base.nodes[i];
        if (n.is_leaf()) {
            for (uint32_t k = n.first; k < n.first + n.count && k < base.prim_indices.size(); ++k) {
                const uint32_t t = base.prim_indices[k];
                const uint32_t mat = t < mesh.triangle_material.size() ? mesh.triangle_material[t] : 0u;
                const Material& m = mat < scene.materials.size() ? scene.materials[mat] : fallback;
                MaterialSums x = triangle_texture_sums(scene, mesh, m, t);
                x.metallic *= double(m.metallic); // factor x texture, as asset_shading
                x.roughness *= double(m.roughness);
                add(sums[i], x);
            }
        } else if (!children_done) {
            stack.push_back({i, true});
            if (n.left < base.nodes.size()) stack.push_back({n.left, false});
            if (n.right < base.nodes.size()) stack.push_back({n.right, false});
        } else {
            if (n.left < base.nodes.size()) add(sums[i], sums[n.left]);
            if (n.right < base.nodes.size()) add(sums[i], sums[n.right]);
        }
    }
    return sums;
}

} // namespace

std::vector<uint32_t> build_node_materials(std::span<const NbvhNode> nodes, const Bvh& base, const Mesh& mesh,
                                           const Scene& scene) {
    bool any = false;
    for (const NbvhNode& n : nodes) any = any || n.base_node < base.nodes.size();
    if (!any || base.empty()) return {};
    const std::vector<MaterialSums> sums = subtree_sums(base, mesh, scene);
    // Parents come before their children (model_file.h): a node without area inherits its parent's word.
    std::vector<uint32_t> parent(nodes.size(), NBVH_NO_CHILD);
    for (uint32_t i = 0; i < nodes.size(); ++i)
        if (nodes[i].has_children() && nodes[i].left + 1 < nodes.size()) parent[nodes[i].left] = parent[nodes[i].left + 1] = i;
    std::vector<uint32_t> words(nodes.size(), nb_pack_node_material(0.0f, 1.0f));
    for (uint32_t i = 0; i < nodes.size(); ++i) {
        const uint32_t b = nodes[i].base_node;
        if (b < sums.size() && sums[b].area > 0.0)
            words[i] = nb_pack_node_material(float(sums[b].metallic / sums[b].area), float(sums[b].roughness / sums[b].area));
        else if (parent[i] < i)
            words[i] = words[parent[i]];
    }
    return words;
}

} // namespace nbvh
