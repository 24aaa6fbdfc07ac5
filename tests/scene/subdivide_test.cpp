// Flat midpoint subdivision (engine/scene/subdivide.h): counts, shared midpoints (watertight stays
// watertight), the same surface (area, planes, winding), interpolated attributes, materials, and the
// limits' one-line errors with the scene untouched.
#include <map>
#include <utility>

#include <gtest/gtest.h>

#include "engine/core/error.h"
#include "engine/scene/subdivide.h"

namespace {

using nbvh::Mesh;

glm::vec3 corner(const Mesh& m, uint32_t t, uint32_t k) { return m.positions[m.indices[3 * t + k]]; }
glm::vec3 face_normal(const Mesh& m, uint32_t t) {
    return glm::cross(corner(m, t, 1) - corner(m, t, 0), corner(m, t, 2) - corner(m, t, 0));
}
double area(const Mesh& m) {
    double a = 0.0;
    for (uint32_t t = 0; t < m.triangle_count(); ++t) a += 0.5 * double(glm::length(face_normal(m, t)));
    return a;
}

// A unit quad in z = 0 with normals, uvs and two materials.
Mesh quad() {
    Mesh m;
    m.name = "quad";
    m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    m.normals.assign(4, glm::vec3(0, 0, 1));
    m.uv0 = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    m.indices = {0, 1, 2, 0, 2, 3};
    m.triangle_material = {3, 7};
    return m;
}

// A regular tetrahedron, outward winding, normals pointing out of the centre (closed: every edge in two
// triangles).
Mesh tetrahedron() {
    Mesh m;
    m.name = "tet";
    m.positions = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
    for (const glm::vec3& p : m.positions) m.normals.push_back(glm::normalize(p));
    m.indices = {0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2};
    m.triangle_material.assign(4, 0);
    return m;
}

std::map<std::pair<uint32_t, uint32_t>, int> edge_uses(const Mesh& m) {
    std::map<std::pair<uint32_t, uint32_t>, int> uses;
    for (uint32_t t = 0; t < m.triangle_count(); ++t)
        for (uint32_t e = 0; e < 3; ++e) {
            const uint32_t a = m.indices[3 * t + e], b = m.indices[3 * t + (e + 1) % 3];
            ++uses[{std::min(a, b), std::max(a, b)}];
        }
    return uses;
}

TEST(Subdivide, QuadCountsAreaPlaneAndWinding) {
    const Mesh q = quad();
    const Mesh s1 = nbvh::subdivide_mesh(q);
    EXPECT_EQ(s1.triangle_count(), 8u);
    EXPECT_EQ(s1.positions.size(), 9u) << "4 corners + 5 edges: the diagonal's midpoint is shared";
    const Mesh s2 = nbvh::subdivide_mesh(s1);
    EXPECT_EQ(s2.triangle_count(), 32u);
    EXPECT_EQ(s2.positions.size(), 25u) << "a 5 x 5 grid of vertices";
    for (const Mesh* m : {&s1, &s2}) {
        EXPECT_NEAR(area(*m), 1.0, 1e-6);
        for (const glm::vec3& p : m->positions) EXPECT_EQ(p.z, 0.0f);
        for (uint32_t t = 0; t < m->triangle_count(); ++t)
            EXPECT_GT(face_normal(*m, t).z, 0.0f) << "winding kept";
        for (size_t v = 0; v < m->positions.size(); ++v) {
            EXPECT_NEAR(m->uv0[v].x, m->positions[v].x, 1e-6f) << "uvs interpolated like the positions";
            EXPECT_NEAR(m->uv0[v].y, m->positions[v].y, 1e-6f);
            EXPECT_EQ(m->normals[v], glm::vec3(0, 0, 1));
        }
        EXPECT_TRUE(m->uv1.empty() && m->tangents.empty()) << "absent attributes stay absent";
    }
    // Each parent's four children keep its material.
    ASSERT_EQ(s1.triangle_material.size(), 8u);
    for (uint32_t t = 0; t < 8; ++t) EXPECT_EQ(s1.triangle_material[t], t < 4 ? 3u : 7u);
    // The children of a parent cover it: their vertices lie in the parent's triangle.
    for (uint32_t t = 0; t < 4; ++t)
        for (uint32_t k = 0; k < 3; ++k) EXPECT_GE(corner(s1, t, k).x, corner(s1, t, k).y) << "in triangle 0";
}

TEST(Subdivide, ClosedMeshStaysClosedWithUnitNormals) {
    Mesh m = tetrahedron();
    for (int level = 1; level <= 3; ++level) {
        m = nbvh::subdivide_mesh(m);
        const auto uses = edge_uses(m);
        for (const auto& [edge, n] : uses) EXPECT_EQ(n, 2) << "edge " << edge.first << "-" << edge.second;
        // Euler characteristic of a sphere: V - E + F = 2.
        EXPECT_EQ(int64_t(m.positions.size()) - int64_t(uses.size()) + int64_t(m.triangle_count()), 2);
        EXPECT_EQ(m.triangle_count(), 4u << (2 * level));
        for (const glm::vec3& n : m.normals) EXPECT_NEAR(glm::length(n), 1.0f, 1e-5f);
    }
    EXPECT_NEAR(area(m), area(tetrahedron()), 1e-4 * area(tetrahedron())) << "the same surface";
}

TEST(Subdivide, TangentsKeepTheirHandedness) {
    Mesh m = quad();
    m.tangents = {{1, 0, 0, -1}, {1, 0, 0, -1}, {0, 1, 0, -1}, {0, 1, 0, -1}};
    const Mesh s = nbvh::subdivide_mesh(m);
    ASSERT_EQ(s.tangents.size(), s.positions.size());
    for (const glm::vec4& t : s.tangents) {
        EXPECT_EQ(t.w, -1.0f);
        EXPECT_NEAR(glm::length(glm::vec3(t)), 1.0f, 1e-6f);
    }
}

TEST(Subdivide, SceneLevelsAndLimits) {
    nbvh::Scene scene;
    scene.meshes = {quad(), tetrahedron()};
    nbvh::subdivide_scene(scene, 0);
    EXPECT_EQ(scene.meshes[0].triangle_count(), 2u) << "0 levels: unchanged";
    nbvh::subdivide_scene(scene, 2);
    EXPECT_EQ(scene.meshes[0].triangle_count(), 32u);
    EXPECT_EQ(scene.meshes[1].triangle_count(), 64u);
    EXPECT_THROW(nbvh::subdivide_scene(scene, nbvh::MAX_SUBDIVISION_LEVELS + 1), nbvh::Error);
    // Above the triangle limit: refused before any work, the scene untouched.
    nbvh::Scene big;
    Mesh strip;
    strip.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    strip.normals.assign(3, glm::vec3(0, 0, 1));
    strip.indices.resize(3 * ((nbvh::MAX_SUBDIVIDED_TRIANGLES >> 8) + 1));
    for (size_t i = 0; i < strip.indices.size(); ++i) strip.indices[i] = uint32_t(i % 3);
    big.meshes = {strip};
    try {
        nbvh::subdivide_scene(big, 4);
        FAIL() << "expected the triangle limit's error";
    } catch (const nbvh::Error& e) {
        EXPECT_NE(std::string(e.what()).find("would become"), std::string::npos) << e.what();
    }
    EXPECT_EQ(big.meshes[0].indices.size(), strip.indices.size());
    nbvh::subdivide_scene(big, 1); // 4x is within the limit
    EXPECT_EQ(big.meshes[0].triangle_count(), 4 * strip.triangle_count());
    EXPECT_EQ(big.meshes[0].positions.size(), 6u) << "the repeated triangle's midpoints are shared";
}

} // namespace
