// Triangle BLAS build and CPU queries (see mesh_bvh.h).
#include "engine/bvh/mesh_bvh.h"

#include "engine/bvh/aabb_ops.h"
#include "engine/core/error.h"
#include "shaders/shared/intersect.h"

namespace nbvh {
namespace {

// Vertex positions of triangle `t`, or false when an index is out of range.
bool triangle_vertices(const Mesh& mesh, uint32_t t, glm::vec3& a, glm::vec3& b, glm::vec3& c) {
    const size_t n = mesh.positions.size();
    const uint32_t i0 = mesh.indices[3 * size_t(t)], i1 = mesh.indices[3 * size_t(t) + 1],
                   i2 = mesh.indices[3 * size_t(t) + 2];
    if (i0 >= n || i1 >= n || i2 >= n) return false;
    a = mesh.positions[i0];
    b = mesh.positions[i1];
    c = mesh.positions[i2];
    return true;
}

// The box of triangle `t`, or false when the builder skips it (an index out of range, a non-finite vertex).
bool triangle_box(const Mesh& mesh, uint32_t t, Aabb& box) {
    glm::vec3 a, b, c;
    if (!triangle_vertices(mesh, t, a, b, c)) return false;
    // Aabb::grow drops NaN (glm min/max), so test the vertices themselves.
    if (!is_finite(a) || !is_finite(b) || !is_finite(c)) return false;
    box = Aabb{};
    box.grow(a);
    box.grow(b);
    box.grow(c);
    return true;
}

} // namespace

BvhBuildOptions default_blas_options() {
    BvhBuildOptions o;
    o.max_leaf_size = 4;
    o.bin_count = 16;
    o.traversal_cost = 1.0f;
    return o;
}

MeshBvh build_mesh_bvh(const Mesh& mesh, const BvhBuildOptions& options) {
    const uint32_t tri_count = mesh.triangle_count();
    std::vector<Aabb> bounds(tri_count); // empty (skipped) unless the triangle is valid
    for (uint32_t t = 0; t < tri_count; ++t) triangle_box(mesh, t, bounds[t]);
    MeshBvh out;
    out.bvh = build_bvh(bounds, options);
    out.vertices.resize(3 * out.bvh.prim_indices.size());
    for (size_t k = 0; k < out.bvh.prim_indices.size(); ++k) {
        triangle_vertices(mesh, out.bvh.prim_indices[k], out.vertices[3 * k], out.vertices[3 * k + 1],
                          out.vertices[3 * k + 2]);
    }
    return out;
}

MeshBvh bounds_only_mesh_bvh(const Mesh& mesh) {
    MeshBvh out;
    out.bounds_only = true;
    Aabb box;
    // The builder's root box is the union of the valid triangles' boxes: min and max in any order give
    // the same floats.
    for (uint32_t t = 0; t < mesh.triangle_count(); ++t)
        if (triangle_box(mesh, t, box)) out.only_bounds.grow(box);
    return out;
}

namespace {

// Shared by closest and any hit: `any` stops at the first accepted triangle.
template <bool any>
bool intersect(const MeshBvh& mesh, const Ray& ray, float tmin, float tmax, Hit& hit,
               const HitFilter* accept = nullptr) {
    if (mesh.bounds_only)
        throw Error("BLAS query on a mesh built for its bounds only (bounds_only_mesh_bvh)");
    bool found = false;
    const glm::vec3* v = mesh.vertices.data();
    const Bvh& bvh = mesh.bvh;
    traverse(bvh, ray, tmin, tmax, [&](uint32_t ni, float, float& t_max) {
        const BvhNode& n = bvh.nodes[ni];
        for (uint32_t k = n.first; k < n.first + n.count; ++k) {
            float t, u, w;
            if (nb_intersect_triangle(ray.org, ray.dir, v[3 * k], v[3 * k + 1], v[3 * k + 2], tmin, t_max, t, u, w)) {
                if (!mesh.single_sided.empty() && mesh.single_sided[k] &&
                    nb_back_facing(v[3 * k], v[3 * k + 1], v[3 * k + 2], ray.dir))
                    continue;
                if (accept && !(*accept)(bvh.prim_indices[k], t, u, w)) continue;
                found = true;
                t_max = t;
                hit = Hit{t, bvh.prim_indices[k], u, w};
                if (any) return true;
            }
        }
        return false;
    });
    return found;
}

} // namespace

bool intersect_closest(const MeshBvh& mesh, const Ray& ray, float tmin, float tmax, Hit& hit,
                       const HitFilter* accept) {
    return intersect<false>(mesh, ray, tmin, tmax, hit, accept);
}

bool intersect_any(const MeshBvh& mesh, const Ray& ray, float tmin, float tmax) {
    Hit h;
    return intersect<true>(mesh, ray, tmin, tmax, h);
}

bool intersect_closest_brute_force(const Mesh& mesh, const Ray& ray, float tmin, float tmax, Hit& hit,
                                   const std::vector<Material>* materials) {
    bool found = false;
    for (uint32_t tri = 0; tri < mesh.triangle_count(); ++tri) {
        glm::vec3 a, b, c;
        if (!triangle_vertices(mesh, tri, a, b, c) || !is_finite(a) || !is_finite(b) || !is_finite(c)) continue;
        float t, u, v;
        if (nb_intersect_triangle(ray.org, ray.dir, a, b, c, tmin, tmax, t, u, v)) {
            if (materials && tri < mesh.triangle_material.size() && mesh.triangle_material[tri] < materials->size() &&
                !(*materials)[mesh.triangle_material[tri]].double_sided && nb_back_facing(a, b, c, ray.dir))
                continue;
            found = true;
            tmax = t;
            hit = Hit{t, tri, u, v};
        }
    }
    return found;
}

std::vector<uint8_t> single_sided_flags(const Mesh& mesh, const MeshBvh& bvh, const std::vector<Material>& materials) {
    std::vector<uint8_t> flags(bvh.bvh.prim_indices.size(), 0);
    bool any = false;
    for (size_t k = 0; k < flags.size(); ++k) {
        const uint32_t tri = bvh.bvh.prim_indices[k];
        const uint32_t m = tri < mesh.triangle_material.size() ? mesh.triangle_material[tri] : 0u;
        flags[k] = m < materials.size() && !materials[m].double_sided;
        any = any || flags[k];
    }
    if (!any) flags.clear();
    return flags;
}

} // namespace nbvh
