#include "engine/scene/simplify.h"

#include <algorithm>
#include <map>
#include <vector>

#include <meshoptimizer.h>

namespace nbvh {

namespace {

// Keeps only the vertices the triangles use, in first-use order; indices rewritten.
Mesh compact(const Mesh& src, std::vector<uint32_t> indices, std::vector<uint32_t> materials) {
    Mesh out;
    out.name = src.name;
    out.split_from = src.split_from;
    std::vector<uint32_t> remap(src.positions.size(), ~0u);
    std::vector<uint32_t> kept;
    for (uint32_t& i : indices) {
        if (remap[i] == ~0u) {
            remap[i] = uint32_t(kept.size());
            kept.push_back(i);
        }
        i = remap[i];
    }
    auto pick = [&](const auto& attr, auto& dst) {
        if (attr.empty()) return;
        dst.reserve(kept.size());
        for (uint32_t v : kept) dst.push_back(attr[v]);
    };
    pick(src.positions, out.positions);
    pick(src.normals, out.normals);
    pick(src.tangents, out.tangents);
    pick(src.uv0, out.uv0);
    pick(src.uv1, out.uv1);
    out.indices = std::move(indices);
    out.triangle_material = std::move(materials);
    return out;
}

} // namespace

Mesh simplify_mesh(const Mesh& mesh, uint32_t target_triangles, SimplifyStats* stats) {
    const uint32_t tris = mesh.triangle_count();
    SimplifyStats st;
    st.source_triangles = tris;
    if (target_triangles >= tris || tris == 0) {
        st.triangles = tris;
        if (stats) *stats = st;
        return mesh;
    }
    // Triangles per material (a mesh without per-triangle materials is one group).
    std::map<uint32_t, std::vector<uint32_t>> groups;
    for (uint32_t t = 0; t < tris; ++t) {
        const uint32_t m = t < mesh.triangle_material.size() ? mesh.triangle_material[t] : 0u;
        auto& g = groups[m];
        g.insert(g.end(), mesh.indices.begin() + 3 * t, mesh.indices.begin() + 3 * t + 3);
    }
    const double ratio = double(target_triangles) / double(tris);
    const float* pos = &mesh.positions[0].x;
    const size_t nv = mesh.positions.size();
    std::vector<uint32_t> indices, materials, dst;
    for (const auto& [material, idx] : groups) {
        const size_t group_tris = idx.size() / 3;
        const size_t target = std::max<size_t>(1, size_t(double(group_tris) * ratio + 0.5));
        dst.resize(idx.size());
        // target_error 1 = the whole mesh extent: the triangle count alone stops the collapse.
        size_t n = meshopt_simplify(dst.data(), idx.data(), idx.size(), pos, nv, sizeof(glm::vec3),
                                    target * 3, 1.0f, 0, nullptr);
        if (n / 3 > target + target / 50 + 1) {
            st.sloppy = true;
            n = meshopt_simplifySloppy(dst.data(), idx.data(), idx.size(), pos, nv, sizeof(glm::vec3),
                                       target * 3, 1.0f, nullptr);
        }
        indices.insert(indices.end(), dst.begin(), dst.begin() + ptrdiff_t(n));
        materials.insert(materials.end(), n / 3, material);
    }
    Mesh out = compact(mesh, std::move(indices), std::move(materials));
    if (mesh.triangle_material.empty()) out.triangle_material.clear();
    st.triangles = out.triangle_count();
    if (stats) *stats = st;
    return out;
}

} // namespace nbvh
