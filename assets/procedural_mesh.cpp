#include "assets/procedural_mesh.h"

#include <cmath>

#include "engine/core/error.h"

namespace nbvh::assets {
namespace {

constexpr float PI = 3.14159265358979323846f;

void add_triangle(Mesh& m, uint32_t a, uint32_t b, uint32_t c, uint32_t material) {
    m.indices.insert(m.indices.end(), {a, b, c});
    m.triangle_material.push_back(material);
}

// One flat quad (CCW as seen from `n`): p0 p1 p2 p3 in order around the face.
void add_quad(Mesh& m, const glm::vec3 p[4], const glm::vec3& n, uint32_t material) {
    const auto base = uint32_t(m.positions.size());
    const glm::vec2 uv[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int i = 0; i < 4; ++i) {
        m.positions.push_back(p[i]);
        m.normals.push_back(n);
        m.uv0.push_back(uv[i]);
    }
    add_triangle(m, base, base + 1, base + 2, material);
    add_triangle(m, base, base + 2, base + 3, material);
}

} // namespace

Mesh make_sphere(const std::string& name, float radius, uint32_t segments, uint32_t rings, uint32_t material) {
    NBVH_CHECK(segments >= 3 && rings >= 2);
    Mesh m;
    m.name = name;
    // (segments+1) columns so the uv seam is clean; poles are rings of coincident vertices.
    for (uint32_t r = 0; r <= rings; ++r) {
        const float theta = PI * float(r) / float(rings); // from +y
        for (uint32_t s = 0; s <= segments; ++s) {
            const float phi = 2.0f * PI * float(s) / float(segments);
            const glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi));
            m.positions.push_back(radius * n);
            m.normals.push_back(n);
            m.uv0.emplace_back(float(s) / float(segments), float(r) / float(rings));
        }
    }
    const uint32_t cols = segments + 1;
    for (uint32_t r = 0; r < rings; ++r)
        for (uint32_t s = 0; s < segments; ++s) {
            const uint32_t a = r * cols + s, b = a + 1, c = a + cols, d = c + 1;
            if (r != 0) add_triangle(m, a, c, b, material);          // skip zero-area pole triangles
            if (r != rings - 1) add_triangle(m, b, c, d, material);
        }
    return m;
}

Mesh make_box(const std::string& name, const glm::vec3& h, uint32_t material) {
    Mesh m;
    m.name = name;
    // For each axis and sign: the face normal and two tangent axes (u, v) with u × v = n.
    const glm::vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int a = 0; a < 3; ++a)
        for (float s : {1.0f, -1.0f}) {
            const glm::vec3 n = s * axes[a];
            const glm::vec3 u = s * axes[(a + 1) % 3], v = axes[(a + 2) % 3];
            const glm::vec3 c = n * h;
            const glm::vec3 du = u * h, dv = v * h;
            const glm::vec3 p[4] = {c - du - dv, c + du - dv, c + du + dv, c - du + dv};
            add_quad(m, p, n, material);
        }
    return m;
}

Mesh make_ground(const std::string& name, float size, uint32_t material) {
    Mesh m;
    m.name = name;
    const float h = 0.5f * size;
    // CCW seen from +y: (-x,+z) -> (+x,+z) -> (+x,-z) -> (-x,-z).
    const glm::vec3 p[4] = {{-h, 0, h}, {h, 0, h}, {h, 0, -h}, {-h, 0, -h}};
    add_quad(m, p, {0, 1, 0}, material);
    return m;
}

Mesh make_cylinder(const std::string& name, float radius, float half_height, uint32_t segments, uint32_t material) {
    NBVH_CHECK(segments >= 3);
    Mesh m;
    m.name = name;
    // Side: two rings with radial normals.
    for (uint32_t s = 0; s <= segments; ++s) {
        const float phi = 2.0f * PI * float(s) / float(segments);
        const glm::vec3 n(std::cos(phi), 0.0f, -std::sin(phi));
        for (float y : {-half_height, half_height}) {
            m.positions.push_back(radius * n + glm::vec3(0, y, 0));
            m.normals.push_back(n);
            m.uv0.emplace_back(float(s) / float(segments), y > 0 ? 1.0f : 0.0f);
        }
    }
    for (uint32_t s = 0; s < segments; ++s) {
        const uint32_t a = 2 * s, b = a + 1, c = a + 2, d = a + 3; // a,c bottom; b,d top
        add_triangle(m, a, c, d, material);
        add_triangle(m, a, d, b, material);
    }
    // Caps: a centre vertex and a fan with flat normals.
    for (float sign : {1.0f, -1.0f}) {
        const glm::vec3 n(0, sign, 0);
        const auto centre = uint32_t(m.positions.size());
        m.positions.emplace_back(0, sign * half_height, 0);
        m.normals.push_back(n);
        m.uv0.emplace_back(0.5f, 0.5f);
        for (uint32_t s = 0; s <= segments; ++s) {
            const float phi = 2.0f * PI * float(s) / float(segments);
            m.positions.emplace_back(radius * std::cos(phi), sign * half_height, -radius * std::sin(phi));
            m.normals.push_back(n);
            m.uv0.emplace_back(0.5f + 0.5f * std::cos(phi), 0.5f + 0.5f * std::sin(phi));
        }
        for (uint32_t s = 0; s < segments; ++s) {
            const uint32_t a = centre + 1 + s, b = a + 1;
            if (sign > 0) add_triangle(m, centre, a, b, material); // phi increases CCW seen from +y
            else add_triangle(m, centre, b, a, material);
        }
    }
    return m;
}

void compute_smooth_normals(Mesh& mesh) {
    std::vector<glm::vec3> acc(mesh.positions.size(), glm::vec3(0.0f));
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const uint32_t i0 = mesh.indices[t], i1 = mesh.indices[t + 1], i2 = mesh.indices[t + 2];
        // Unnormalised cross product = 2·area·n: area weighting for free.
        const glm::vec3 n = glm::cross(mesh.positions[i1] - mesh.positions[i0], mesh.positions[i2] - mesh.positions[i0]);
        acc[i0] += n, acc[i1] += n, acc[i2] += n;
    }
    mesh.normals.resize(mesh.positions.size());
    for (size_t i = 0; i < acc.size(); ++i) {
        const float len = glm::length(acc[i]);
        mesh.normals[i] = (len > 0.0f && std::isfinite(len)) ? acc[i] / len : glm::vec3(0, 1, 0);
    }
}

} // namespace nbvh::assets
