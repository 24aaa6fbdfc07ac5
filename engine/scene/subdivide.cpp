#include "engine/scene/subdivide.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "engine/core/error.h"
#include "engine/core/log.h"

namespace nbvh {

namespace {

glm::vec3 unit_or(const glm::vec3& v, const glm::vec3& fallback) {
    const float len2 = glm::dot(v, v);
    return len2 > 0.0f ? v / std::sqrt(len2) : fallback;
}

// Appends the midpoint vertex of edge (a, b) to every attribute array of `m` and returns its index.
uint32_t add_midpoint(Mesh& m, uint32_t a, uint32_t b) {
    const uint32_t v = uint32_t(m.positions.size());
    m.positions.push_back(0.5f * (m.positions[a] + m.positions[b]));
    if (!m.normals.empty()) m.normals.push_back(unit_or(m.normals[a] + m.normals[b], m.normals[a]));
    if (!m.tangents.empty()) {
        const glm::vec3 t =
            unit_or(glm::vec3(m.tangents[a]) + glm::vec3(m.tangents[b]), glm::vec3(m.tangents[a]));
        m.tangents.push_back(glm::vec4(t, m.tangents[a].w));
    }
    if (!m.uv0.empty()) m.uv0.push_back(0.5f * (m.uv0[a] + m.uv0[b]));
    if (!m.uv1.empty()) m.uv1.push_back(0.5f * (m.uv1[a] + m.uv1[b]));
    return v;
}

} // namespace

Mesh subdivide_mesh(const Mesh& mesh) {
    const uint32_t tris = mesh.triangle_count();
    // Every edge once, keyed (min, max) and sorted: a midpoint is shared by the triangles on both sides.
    struct Edge {
        uint64_t key;
        uint32_t slot; // triangle * 3 + edge (edge e runs from corner e to corner (e + 1) % 3)
    };
    std::vector<Edge> edges(size_t(tris) * 3);
    for (uint32_t t = 0; t < tris; ++t)
        for (uint32_t e = 0; e < 3; ++e) {
            const uint32_t a = mesh.indices[3 * t + e], b = mesh.indices[3 * t + (e + 1) % 3];
            edges[3 * t + e] = {(uint64_t(std::min(a, b)) << 32) | std::max(a, b), 3 * t + e};
        }
    std::sort(edges.begin(), edges.end(),
              [](const Edge& x, const Edge& y) { return x.key != y.key ? x.key < y.key : x.slot < y.slot; });
    Mesh out = mesh;
    out.indices.clear();
    out.triangle_material.clear();
    std::vector<uint32_t> midpoint(edges.size());
    for (size_t i = 0; i < edges.size(); ++i) {
        const bool first = i == 0 || edges[i].key != edges[i - 1].key;
        midpoint[edges[i].slot] =
            first ? add_midpoint(out, uint32_t(edges[i].key >> 32), uint32_t(edges[i].key))
                  : midpoint[edges[i - 1].slot];
    }
    out.indices.reserve(size_t(tris) * 12);
    for (uint32_t t = 0; t < tris; ++t) {
        const uint32_t a = mesh.indices[3 * t], b = mesh.indices[3 * t + 1], c = mesh.indices[3 * t + 2];
        const uint32_t ab = midpoint[3 * t], bc = midpoint[3 * t + 1], ca = midpoint[3 * t + 2];
        // Corner triangles first, the middle one last; all keep the parent's winding.
        out.indices.insert(out.indices.end(), {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca});
        if (!mesh.triangle_material.empty())
            out.triangle_material.insert(out.triangle_material.end(), 4, mesh.triangle_material[t]);
    }
    return out;
}

void subdivide_scene(Scene& scene, uint32_t levels) {
    if (levels == 0) return;
    if (levels > MAX_SUBDIVISION_LEVELS)
        throw Error(strfmt("--subdivide %u: at most %u levels (%ux the triangles)", levels,
                           MAX_SUBDIVISION_LEVELS, 1u << (2 * MAX_SUBDIVISION_LEVELS)));
    uint64_t triangles = 0;
    for (const Mesh& m : scene.meshes) triangles += uint64_t(m.triangle_count());
    const uint64_t result = triangles << (2 * levels);
    if (result > MAX_SUBDIVIDED_TRIANGLES)
        throw Error(strfmt("--subdivide %u: %llu triangles would become %llu (at most %llu)", levels,
                           (unsigned long long)triangles, (unsigned long long)result,
                           (unsigned long long)MAX_SUBDIVIDED_TRIANGLES));
    for (Mesh& m : scene.meshes)
        for (uint32_t l = 0; l < levels; ++l) m = subdivide_mesh(m);
    log_info("--subdivide %u: %llu triangles -> %llu (flat midpoint subdivision, the same surface)", levels,
             (unsigned long long)triangles, (unsigned long long)result);
}

} // namespace nbvh
