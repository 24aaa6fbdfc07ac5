// Invariants every loaded Scene must satisfy (shared by the scene tests).
#pragma once
#include <cmath>

#include <gtest/gtest.h>

#include "engine/scene/scene.h"

namespace nbvh::test {

inline bool finite_vec(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Positions and normals finite, normals unit, indices and materials in range, tangents unit, bounds finite.
inline void expect_scene_sane(const Scene& scene) {
    ASSERT_FALSE(scene.materials.empty());
    for (const Mesh& m : scene.meshes) {
        EXPECT_EQ(m.normals.size(), m.positions.size()) << m.name;
        EXPECT_EQ(m.indices.size() % 3, 0u) << m.name;
        EXPECT_EQ(m.triangle_material.size(), m.triangle_count()) << m.name;
        EXPECT_GT(m.triangle_count(), 0u) << "empty meshes must not be kept: " << m.name;
        size_t bad_pos = 0, bad_nrm = 0, bad_idx = 0, bad_mat = 0, bad_tan = 0;
        for (const glm::vec3& p : m.positions) bad_pos += !finite_vec(p);
        for (const glm::vec3& n : m.normals) bad_nrm += !finite_vec(n) || std::fabs(glm::length(n) - 1.0f) > 1e-3f;
        for (uint32_t i : m.indices) bad_idx += i >= m.positions.size();
        for (uint32_t t : m.triangle_material) bad_mat += t >= scene.materials.size();
        if (!m.tangents.empty()) {
            EXPECT_EQ(m.tangents.size(), m.positions.size()) << m.name;
            for (const glm::vec4& t : m.tangents)
                bad_tan += !finite_vec(glm::vec3(t)) || std::fabs(glm::length(glm::vec3(t)) - 1.0f) > 1e-3f ||
                           std::fabs(std::fabs(t.w) - 1.0f) > 0.0f;
        }
        if (!m.uv0.empty()) {
            EXPECT_EQ(m.uv0.size(), m.positions.size()) << m.name;
        }
        EXPECT_EQ(bad_pos, 0u) << m.name;
        EXPECT_EQ(bad_nrm, 0u) << m.name;
        EXPECT_EQ(bad_idx, 0u) << m.name;
        EXPECT_EQ(bad_mat, 0u) << m.name;
        EXPECT_EQ(bad_tan, 0u) << m.name;
    }
    for (const Instance& inst : scene.instances) {
        ASSERT_LT(inst.mesh, scene.meshes.size());
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) EXPECT_TRUE(std::isfinite(inst.object_to_world[c][r]));
    }
    const Aabb b = scene.world_bounds();
    if (!b.empty()) {
        EXPECT_TRUE(finite_vec(b.lo));
        EXPECT_TRUE(finite_vec(b.hi));
    }
    for (const Texture& t : scene.textures) EXPECT_EQ(t.rgba8.size(), size_t(t.width) * t.height * 4) << t.name;
}

} // namespace nbvh::test
