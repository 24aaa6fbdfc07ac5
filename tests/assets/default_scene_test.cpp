#include <gtest/gtest.h>

#include <cmath>

#include "assets/default_scene.h"
#include "assets/procedural_mesh.h"
#include "assets/rope_knot.h"

using namespace nbvh;

namespace {
bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
} // namespace

TEST(DefaultScene, ContentsAreCompleteAndValid) {
    const Scene s = assets::make_default_scene();
    ASSERT_FALSE(s.meshes.empty());
    ASSERT_FALSE(s.materials.empty());
    EXPECT_TRUE(s.has_camera);
    EXPECT_FALSE(s.environment.empty());
    EXPECT_EQ(s.environment.rgb.size(), size_t(s.environment.width) * s.environment.height * 3);

    uint64_t triangles = 0;
    for (const Mesh& m : s.meshes) {
        triangles += m.triangle_count();
        ASSERT_EQ(m.normals.size(), m.positions.size()) << m.name;
        ASSERT_EQ(m.triangle_material.size(), m.triangle_count()) << m.name;
        EXPECT_TRUE(m.uv0.empty() || m.uv0.size() == m.positions.size()) << m.name;
        for (const glm::vec3& p : m.positions) ASSERT_TRUE(finite(p)) << m.name;
        for (const glm::vec3& n : m.normals) {
            ASSERT_TRUE(finite(n)) << m.name;
            ASSERT_NEAR(glm::length(n), 1.0f, 1e-4f) << m.name;
        }
        for (uint32_t i : m.indices) ASSERT_LT(i, m.positions.size()) << m.name;
        for (uint32_t mat : m.triangle_material) ASSERT_LT(mat, s.materials.size()) << m.name;
    }
    EXPECT_GT(triangles, 300000u);
    EXPECT_LT(triangles, 600000u);

    // Textures referenced exist and have their bytes.
    for (const Material& mat : s.materials)
        if (mat.base_color_tex.texture >= 0) {
            ASSERT_LT(size_t(mat.base_color_tex.texture), s.textures.size());
            const Texture& t = s.textures[size_t(mat.base_color_tex.texture)];
            EXPECT_EQ(t.rgba8.size(), size_t(t.width) * t.height * 4);
        }

    // Exactly one emissive object, used by an instance.
    int emissive_instances = 0, neural_instances = 0;
    for (const Instance& inst : s.instances) {
        ASSERT_LT(inst.mesh, s.meshes.size());
        const Mesh& m = s.meshes[inst.mesh];
        bool emissive = false;
        for (uint32_t mat : m.triangle_material) emissive |= glm::length(s.materials[mat].emissive) > 0.0f;
        emissive_instances += emissive ? 1 : 0;
        if (inst.neural) {
            ++neural_instances;
            EXPECT_NE(inst.name.find("neural_"), std::string::npos);
            EXPECT_GT(m.triangle_count(), 300000u); // the detailed asset
        }
    }
    EXPECT_EQ(emissive_instances, 1);
    EXPECT_EQ(neural_instances, 1);

    // The camera looks at the neural asset, and everything sits on or above the ground.
    const Aabb world = s.world_bounds();
    EXPECT_GE(world.lo.y, -1e-4f);
    EXPECT_GT(glm::length(s.camera.eye - s.camera.target), 1.0f);
}

TEST(DefaultScene, IsDeterministic) {
    const Scene a = assets::make_default_scene(), b = assets::make_default_scene();
    ASSERT_EQ(a.meshes.size(), b.meshes.size());
    for (size_t i = 0; i < a.meshes.size(); ++i) {
        EXPECT_EQ(a.meshes[i].positions, b.meshes[i].positions);
        EXPECT_EQ(a.meshes[i].indices, b.meshes[i].indices);
    }
    EXPECT_EQ(a.environment.rgb, b.environment.rgb);
}

TEST(RopeKnot, ClosedTubeWithOutwardNormals) {
    assets::RopeKnotParams p;
    p.segments_along = 64;
    p.segments_around = 12;
    const Mesh m = assets::make_rope_knot(p, 0);
    EXPECT_EQ(m.triangle_count(), 2u * 64 * 12);
    EXPECT_EQ(m.positions.size(), 64u * 12);
    // Watertight: every undirected edge is shared by exactly two triangles (Euler: V − E + F = 0, a torus).
    const size_t v = m.positions.size(), f = m.triangle_count(), e = 3 * f / 2;
    EXPECT_EQ(int64_t(v) - int64_t(e) + int64_t(f), 0);
    // Geometric face normals agree with the smooth vertex normals (outward winding).
    int agree = 0;
    for (size_t t = 0; t < m.indices.size(); t += 3) {
        const glm::vec3 a = m.positions[m.indices[t]], b = m.positions[m.indices[t + 1]], c = m.positions[m.indices[t + 2]];
        const glm::vec3 fn = glm::cross(b - a, c - a);
        agree += glm::dot(fn, m.normals[m.indices[t]]) > 0.0f ? 1 : 0;
    }
    EXPECT_EQ(agree, int(f));
}

TEST(ProceduralMesh, PrimitivesHaveOutwardWinding) {
    for (const Mesh& m : {assets::make_sphere("s", 1.0f, 16, 8, 0), assets::make_box("b", glm::vec3(1.0f), 0),
                          assets::make_cylinder("c", 1.0f, 0.5f, 16, 0), assets::make_ground("g", 2.0f, 0)}) {
        for (size_t t = 0; t < m.indices.size(); t += 3) {
            const glm::vec3 a = m.positions[m.indices[t]], b = m.positions[m.indices[t + 1]], c = m.positions[m.indices[t + 2]];
            const glm::vec3 fn = glm::cross(b - a, c - a);
            ASSERT_GT(glm::length(fn), 0.0f) << m.name << " triangle " << t / 3;
            const glm::vec3 n = m.normals[m.indices[t]] + m.normals[m.indices[t + 1]] + m.normals[m.indices[t + 2]];
            EXPECT_GT(glm::dot(fn, n), 0.0f) << m.name << " triangle " << t / 3;
        }
    }
}
