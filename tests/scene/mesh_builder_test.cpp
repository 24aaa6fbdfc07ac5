// Mesh building from hand-made primitives, strip/fan conversion, globs, KHR_texture_transform matrix.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "engine/scene/gltf_material.h"
#include "engine/scene/mesh_builder.h"
#include "engine/scene/scene_stats.h"

namespace {

using nbvh::PrimitiveData;

PrimitiveData quad() {
    PrimitiveData p;
    p.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    p.indices = {0, 1, 2, 0, 2, 3};
    return p;
}

TEST(MeshBuilder, GeneratesUnitNormalsAndDropsBadTriangles) {
    std::vector<PrimitiveData> prims{quad()};
    const float nan = std::numeric_limits<float>::quiet_NaN();
    prims[0].positions.push_back({nan, 0, 0});                  // vertex 4
    prims[0].indices.insert(prims[0].indices.end(), {0, 1, 4}); // non-finite
    prims[0].indices.insert(prims[0].indices.end(), {0, 1, 9}); // out of range
    prims[0].indices.insert(prims[0].indices.end(), {2, 2, 2}); // zero area: kept
    nbvh::MeshBuildReport r;
    const nbvh::Mesh m = nbvh::build_mesh("q", prims, r);
    EXPECT_EQ(m.triangle_count(), 3u);
    EXPECT_EQ(r.dropped_non_finite, 1u);
    EXPECT_EQ(r.dropped_out_of_range_index, 1u);
    EXPECT_EQ(r.zero_area_triangles, 1u);
    EXPECT_EQ(m.positions.size(), 4u) << "the NaN vertex is not referenced any more and is compacted away";
    for (const glm::vec3& n : m.normals) EXPECT_NEAR(glm::distance(n, glm::vec3(0, 0, 1)), 0.0f, 1e-6f);
}

TEST(MeshBuilder, RepairsZeroAndNonUnitNormals) {
    std::vector<PrimitiveData> prims{quad()};
    prims[0].normals = {{0, 0, 0}, {0, 0, 5}, {0, 0, 1}, {NAN, 0, 0}};
    nbvh::MeshBuildReport r;
    const nbvh::Mesh m = nbvh::build_mesh("q", prims, r);
    EXPECT_EQ(r.repaired_normals, 3u);
    for (const glm::vec3& n : m.normals) EXPECT_NEAR(glm::distance(n, glm::vec3(0, 0, 1)), 0.0f, 1e-6f);
}

TEST(MeshBuilder, AllZeroAreaMeshIsEmptied) {
    PrimitiveData p;
    p.positions = {{1, 1, 1}, {1, 1, 1}, {2, 2, 2}};
    p.indices = {0, 1, 2};
    std::vector<PrimitiveData> prims{p};
    nbvh::MeshBuildReport r;
    EXPECT_EQ(nbvh::build_mesh("z", prims, r).triangle_count(), 0u);
    EXPECT_TRUE(r.all_zero_area);
}

TEST(MeshBuilder, HugeCoordinatesAreCounted) {
    std::vector<PrimitiveData> prims{quad()};
    for (glm::vec3& v : prims[0].positions) v *= 1e30f;
    nbvh::MeshBuildReport r;
    EXPECT_EQ(nbvh::build_mesh("h", prims, r).triangle_count(), 0u);
    EXPECT_EQ(r.dropped_huge, 2u);
}

TEST(MeshBuilder, TangentsFromUvsAndFallbackForDegenerateUvs) {
    std::vector<PrimitiveData> prims{quad(), quad()};
    prims[0].uv0 = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    prims[0].needs_tangents = true;
    prims[1].uv0 = {{0, 0}, {0, 0}, {0, 0}, {0, 0}}; // degenerate: no UV information
    prims[1].needs_tangents = true;
    prims[1].material = 1;
    nbvh::MeshBuildReport r;
    const nbvh::Mesh m = nbvh::build_mesh("t", prims, r);
    ASSERT_EQ(m.tangents.size(), 8u);
    EXPECT_EQ(m.triangle_material, (std::vector<uint32_t>{0, 0, 1, 1}));
    for (int v = 0; v < 4; ++v) {
        EXPECT_NEAR(glm::distance(glm::vec3(m.tangents[v]), glm::vec3(1, 0, 0)), 0.0f, 1e-5f);
        EXPECT_EQ(m.tangents[v].w, 1.0f);
    }
    EXPECT_EQ(r.degenerate_uv_tangents, 4u);
    for (int v = 4; v < 8; ++v) {
        EXPECT_NEAR(glm::length(glm::vec3(m.tangents[v])), 1.0f, 1e-5f);
        EXPECT_NEAR(glm::dot(glm::vec3(m.tangents[v]), m.normals[v]), 0.0f, 1e-5f);
    }
}

TEST(MeshBuilder, StripAndFanConversion) {
    EXPECT_EQ(nbvh::strip_to_list({0, 1, 2, 3, 4}), (std::vector<uint32_t>{0, 1, 2, 1, 3, 2, 2, 3, 4}));
    EXPECT_EQ(nbvh::fan_to_list({0, 1, 2, 3}), (std::vector<uint32_t>{1, 2, 0, 2, 3, 0}));
    EXPECT_TRUE(nbvh::strip_to_list({0, 1}).empty());
}

TEST(SceneStats, GlobMatch) {
    EXPECT_TRUE(nbvh::glob_match("Pawn*", "Pawn_Body_B1"));
    EXPECT_TRUE(nbvh::glob_match("*", ""));
    EXPECT_TRUE(nbvh::glob_match("*_B?", "King_B1"));
    EXPECT_TRUE(nbvh::glob_match("a*b*c", "aXXbYYbc"));
    EXPECT_FALSE(nbvh::glob_match("Pawn*", "King"));
    EXPECT_FALSE(nbvh::glob_match("?", ""));
    EXPECT_FALSE(nbvh::glob_match("abc", "abcd"));
}

TEST(TextureTransform, MatchesKhrSpecification) {
    // offset (0.5, 0), rotation 90 deg, scale 2: uv (1, 0) -> scale (2, 0) -> rotate (0, -2) -> offset (0.5, -2).
    const glm::mat3 m = nbvh::gltf::texture_transform({0.5f, 0.0f}, 1.5707963f, {2.0f, 2.0f});
    const glm::vec3 uv = m * glm::vec3(1.0f, 0.0f, 1.0f);
    EXPECT_NEAR(uv.x, 0.5f, 1e-5f);
    EXPECT_NEAR(uv.y, -2.0f, 1e-5f);
    // The extension's example: offset (0, 1), rotation pi/2, scale 0.5 uses the lower-left quadrant.
    const glm::mat3 q = nbvh::gltf::texture_transform({0.0f, 1.0f}, 1.57079632679f, {0.5f, 0.5f});
    const glm::vec3 a = q * glm::vec3(0, 0, 1), b = q * glm::vec3(1, 1, 1);
    EXPECT_NEAR(glm::distance(glm::vec2(a), glm::vec2(0.0f, 1.0f)), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::distance(glm::vec2(b), glm::vec2(0.5f, 0.5f)), 0.0f, 1e-5f);
}

} // namespace
