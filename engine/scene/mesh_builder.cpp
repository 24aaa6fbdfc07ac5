#include "engine/scene/mesh_builder.h"

#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

namespace nbvh {
namespace {

constexpr uint32_t UNUSED = std::numeric_limits<uint32_t>::max();

bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool finite4(const glm::vec4& v) { return finite3(glm::vec3(v)) && std::isfinite(v.w); }
bool in_range(const glm::vec3& v) {
    return std::fabs(v.x) <= MAX_COORDINATE && std::fabs(v.y) <= MAX_COORDINATE && std::fabs(v.z) <= MAX_COORDINATE;
}

// Face normal times twice the area, in double so large-but-accepted coordinates cannot overflow.
glm::dvec3 area_normal(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    return glm::cross(glm::dvec3(b) - glm::dvec3(a), glm::dvec3(c) - glm::dvec3(a));
}

// Normalises in double; returns false when the vector has no usable direction.
bool safe_normalize(const glm::dvec3& v, glm::vec3& out) {
    const double len = glm::length(v);
    if (!(len > 1e-300) || !std::isfinite(len)) return false;
    out = glm::vec3(v / len);
    return finite3(out);
}

} // namespace

glm::vec3 any_perpendicular(const glm::vec3& n) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float b = n.x * n.y * a;
    return glm::vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
}

std::vector<uint32_t> strip_to_list(const std::vector<uint32_t>& strip) {
    std::vector<uint32_t> out;
    if (strip.size() < 3) return out;
    out.reserve((strip.size() - 2) * 3);
    for (size_t i = 0; i + 2 < strip.size(); ++i) {
        const size_t odd = i % 2;
        out.insert(out.end(), {strip[i], strip[i + 1 + odd], strip[i + 2 - odd]});
    }
    return out;
}

std::vector<uint32_t> fan_to_list(const std::vector<uint32_t>& fan) {
    std::vector<uint32_t> out;
    if (fan.size() < 3) return out;
    out.reserve((fan.size() - 2) * 3);
    for (size_t i = 0; i + 2 < fan.size(); ++i) out.insert(out.end(), {fan[i + 1], fan[i + 2], fan[0]});
    return out;
}

Mesh build_mesh(const std::string& name, std::vector<PrimitiveData>& primitives, MeshBuildReport& report) {
    Mesh mesh;
    mesh.name = name;
    bool any_uv0 = false, any_uv1 = false, any_tangent_need = false;
    for (const PrimitiveData& p : primitives) {
        any_uv0 |= !p.uv0.empty();
        any_uv1 |= !p.uv1.empty();
        any_tangent_need |= p.needs_tangents;
    }
    // Per output vertex: was a usable normal / tangent given?
    std::vector<uint8_t> normal_ok, tangent_ok;
    std::vector<uint32_t> tangent_uv_set;

    for (PrimitiveData& p : primitives) {
        const size_t nv = p.positions.size();
        std::vector<uint32_t> remap(nv, UNUSED);
        for (size_t t = 0; t + 3 <= p.indices.size(); t += 3) {
            const uint32_t i0 = p.indices[t], i1 = p.indices[t + 1], i2 = p.indices[t + 2];
            if (i0 >= nv || i1 >= nv || i2 >= nv) {
                ++report.dropped_out_of_range_index;
                continue;
            }
            const glm::vec3 &a = p.positions[i0], &b = p.positions[i1], &c = p.positions[i2];
            if (!finite3(a) || !finite3(b) || !finite3(c)) {
                ++report.dropped_non_finite;
                continue;
            }
            if (!in_range(a) || !in_range(b) || !in_range(c)) {
                ++report.dropped_huge;
                continue;
            }
            for (const uint32_t i : {i0, i1, i2}) {
                if (remap[i] == UNUSED) {
                    remap[i] = uint32_t(mesh.positions.size());
                    mesh.positions.push_back(p.positions[i]);
                    const bool has_n = p.normals.size() == nv;
                    mesh.normals.push_back(has_n ? p.normals[i] : glm::vec3(0.0f));
                    normal_ok.push_back(has_n ? 1 : 0);
                    if (any_uv0) mesh.uv0.push_back(p.uv0.size() == nv ? p.uv0[i] : glm::vec2(0.0f));
                    if (any_uv1) mesh.uv1.push_back(p.uv1.size() == nv ? p.uv1[i] : glm::vec2(0.0f));
                    if (any_tangent_need) {
                        const bool has_t = p.needs_tangents && p.tangents.size() == nv;
                        mesh.tangents.push_back(has_t ? p.tangents[i] : glm::vec4(0.0f));
                        tangent_ok.push_back(has_t ? 1 : 0);
                        tangent_uv_set.push_back(p.normal_map_uv_set);
                    }
                }
                mesh.indices.push_back(remap[i]);
            }
            mesh.triangle_material.push_back(p.material);
        }
        // Free the primitive's memory early: large scans hold several copies otherwise.
        p = PrimitiveData();
    }

    // Zero-area triangles are legal glTF (a scan's bishop has some): keep them (a watertight intersection test
    // never hits them) but a mesh whose every triangle has zero area is nothing to render or train on.
    const uint32_t tri_count = mesh.triangle_count();
    std::vector<glm::dvec3> face(tri_count);
    uint64_t zero_area = 0;
    for (uint32_t t = 0; t < tri_count; ++t) {
        const uint32_t* i = &mesh.indices[3 * size_t(t)];
        face[t] = area_normal(mesh.positions[i[0]], mesh.positions[i[1]], mesh.positions[i[2]]);
        if (glm::dot(face[t], face[t]) == 0.0) ++zero_area;
    }
    report.zero_area_triangles += zero_area;
    if (tri_count > 0 && zero_area == tri_count) {
        report.all_zero_area = true;
        Mesh empty;
        empty.name = name;
        return empty;
    }

    // Normals: keep given unit normals, renormalise non-unit ones, regenerate zero / non-finite / absent ones
    // from area-weighted face normals (vertices shared by faces = smooth; unshared = flat).
    bool need_generated = false;
    for (size_t v = 0; v < mesh.normals.size(); ++v) {
        if (!normal_ok[v]) {
            need_generated = true;
            ++report.generated_normals;
            continue;
        }
        glm::vec3 n;
        const glm::vec3 given = mesh.normals[v];
        if (finite3(given) && safe_normalize(glm::dvec3(given), n)) {
            if (std::fabs(glm::dot(given, given) - 1.0f) > 1e-3f) ++report.repaired_normals;
            mesh.normals[v] = n;
        } else {
            normal_ok[v] = 0;
            need_generated = true;
            ++report.repaired_normals;
        }
    }
    if (need_generated) {
        std::vector<glm::dvec3> acc(mesh.positions.size(), glm::dvec3(0.0));
        for (uint32_t t = 0; t < tri_count; ++t)
            for (int k = 0; k < 3; ++k) acc[mesh.indices[3 * size_t(t) + k]] += face[t];
        for (size_t v = 0; v < mesh.normals.size(); ++v) {
            if (normal_ok[v]) continue;
            glm::vec3 n;
            mesh.normals[v] = safe_normalize(acc[v], n) ? n : glm::vec3(0.0f, 1.0f, 0.0f);
        }
    }

    // Tangents (only when a material of this mesh has a normal map): accumulate per-triangle UV derivatives
    // (dP/du), orthogonalise against the normal, handedness from dP/dv (glTF: B = cross(N, T.xyz) * T.w).
    if (any_tangent_need) {
        std::vector<glm::dvec3> tan(mesh.positions.size(), glm::dvec3(0.0)), bit(mesh.positions.size(), glm::dvec3(0.0));
        bool need = false;
        for (size_t v = 0; v < mesh.tangents.size(); ++v) {
            const glm::vec4 t = mesh.tangents[v];
            glm::vec3 dir;
            if (tangent_ok[v] && finite4(t) && safe_normalize(glm::dvec3(glm::vec3(t)), dir)) {
                mesh.tangents[v] = glm::vec4(dir, t.w < 0.0f ? -1.0f : 1.0f);
            } else {
                tangent_ok[v] = 0;
                need = true;
            }
        }
        if (need) {
            for (uint32_t t = 0; t < tri_count; ++t) {
                const uint32_t* i = &mesh.indices[3 * size_t(t)];
                const std::vector<glm::vec2>& uv = tangent_uv_set[i[0]] == 1 && !mesh.uv1.empty() ? mesh.uv1 : mesh.uv0;
                if (uv.empty()) break;
                const glm::dvec3 e1 = glm::dvec3(mesh.positions[i[1]]) - glm::dvec3(mesh.positions[i[0]]);
                const glm::dvec3 e2 = glm::dvec3(mesh.positions[i[2]]) - glm::dvec3(mesh.positions[i[0]]);
                const glm::dvec2 d1 = glm::dvec2(uv[i[1]]) - glm::dvec2(uv[i[0]]);
                const glm::dvec2 d2 = glm::dvec2(uv[i[2]]) - glm::dvec2(uv[i[0]]);
                const double det = d1.x * d2.y - d2.x * d1.y;
                if (!std::isfinite(det) || std::fabs(det) < 1e-20) continue; // degenerate UVs: no information
                const double r = 1.0 / det;
                const glm::dvec3 sdir = (e1 * d2.y - e2 * d1.y) * r;
                const glm::dvec3 tdir = (e2 * d1.x - e1 * d2.x) * r;
                if (!std::isfinite(glm::dot(sdir, sdir)) || !std::isfinite(glm::dot(tdir, tdir))) continue;
                for (int k = 0; k < 3; ++k) {
                    tan[i[k]] += sdir;
                    bit[i[k]] += tdir;
                }
            }
            for (size_t v = 0; v < mesh.tangents.size(); ++v) {
                if (tangent_ok[v]) continue;
                const glm::dvec3 n(mesh.normals[v]);
                glm::vec3 t;
                if (safe_normalize(tan[v] - n * glm::dot(n, tan[v]), t)) {
                    const float w = glm::dot(glm::cross(n, tan[v]), bit[v]) < 0.0 ? -1.0f : 1.0f;
                    mesh.tangents[v] = glm::vec4(t, w);
                } else {
                    mesh.tangents[v] = glm::vec4(any_perpendicular(mesh.normals[v]), 1.0f);
                    ++report.degenerate_uv_tangents;
                }
                ++report.generated_tangents;
            }
        }
    }
    return mesh;
}

} // namespace nbvh
