// The equal-memory decimation baseline (engine/scene/simplify.h, engine/render/decimation.h, issue 11):
// meshoptimizer reaches a triangle target per material, and decimate_to_budget picks a triangle budget
// whose mesh + BLAS bytes are within 5 % of a neural model's GPU bytes.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "engine/bvh/wide_bvh.h"
#include "engine/neural/level_table.h"
#include "engine/render/decimation.h"
#include "engine/render/gpu_memory.h"
#include "engine/scene/simplify.h"
#include "tests/model/tiny_model.h"

namespace {
using namespace nbvh;

// A UV sphere of 2 * rings * segments triangles, the upper half material 0 and the lower half material 1.
Mesh sphere(uint32_t rings, uint32_t segments) {
    Mesh m;
    m.name = "sphere";
    for (uint32_t r = 0; r <= rings; ++r)
        for (uint32_t s = 0; s <= segments; ++s) {
            const float th = 3.14159265f * float(r) / float(rings),
                        ph = 6.2831853f * float(s) / float(segments);
            const glm::vec3 p(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
            m.positions.push_back(p);
            m.normals.push_back(p);
            m.uv0.push_back({float(s) / float(segments), float(r) / float(rings)});
        }
    for (uint32_t r = 0; r < rings; ++r)
        for (uint32_t s = 0; s < segments; ++s) {
            const uint32_t a = r * (segments + 1) + s, b = a + 1, c = a + segments + 1, d = c + 1;
            for (uint32_t i : {a, c, b, b, c, d}) m.indices.push_back(i);
            m.triangle_material.push_back(r < rings / 2 ? 0u : 1u);
            m.triangle_material.push_back(r < rings / 2 ? 0u : 1u);
        }
    return m;
}

Scene scene_of(Mesh mesh) {
    Scene s;
    s.meshes.push_back(std::move(mesh));
    s.materials.resize(2);
    Instance i;
    i.neural = true;
    s.instances.push_back(i);
    return s;
}

TEST(Simplify, ReachesTheTargetPerMaterialAndDropsUnusedVertices) {
    const Mesh src = sphere(128, 256); // 65,536 triangles
    SimplifyStats st;
    const Mesh out = simplify_mesh(src, 4096, &st);
    EXPECT_EQ(st.source_triangles, src.triangle_count());
    EXPECT_NEAR(double(out.triangle_count()), 4096.0, 4096.0 * 0.05);
    EXPECT_EQ(st.triangles, out.triangle_count());
    ASSERT_EQ(out.triangle_material.size(), out.triangle_count());
    uint32_t upper = 0;
    for (uint32_t t = 0; t < out.triangle_count(); ++t) {
        const glm::vec3 c = (out.positions[out.indices[3 * t]] + out.positions[out.indices[3 * t + 1]] +
                             out.positions[out.indices[3 * t + 2]]) /
                            3.0f;
        if (out.triangle_material[t] == 0) {
            upper++;
            EXPECT_GT(c.y, -0.05f) << t; // material 0 stays on the upper half
        }
    }
    EXPECT_NEAR(double(upper), 2048.0, 2048.0 * 0.05);
    std::vector<bool> used(out.positions.size(), false);
    for (uint32_t i : out.indices) {
        ASSERT_LT(i, out.positions.size());
        used[i] = true;
    }
    for (bool u : used) EXPECT_TRUE(u);
    EXPECT_EQ(out.normals.size(), out.positions.size());
    EXPECT_EQ(out.uv0.size(), out.positions.size());
    // At or above the source count: unchanged.
    EXPECT_EQ(simplify_mesh(src, src.triangle_count()).triangle_count(), src.triangle_count());
}

TEST(Decimation, BudgetWithinFivePercentOfTheNeuralBytes) {
    const Scene scene = scene_of(sphere(256, 512)); // 262,144 triangles
    const uint32_t meshes[] = {0};
    const uint64_t full = render::mesh_gpu_bytes(scene.meshes[0]);
    for (uint32_t log2 : {12u, 14u}) {
        // The GPU bytes of a model with this hash table (tiny_model.h's tree and MLP).
        NeuralModel model = test::make_tiny_model();
        model.cfg.log2_hash_size = log2;
        model.levels = neural::make_level_table(model.cfg);
        model.grid.assign(neural::level_table_entries(model.levels) * model.cfg.grid_features, 0);
        const uint64_t budget = render::neural_gpu_bytes(model).total();
        ASSERT_LT(budget, full / 4) << log2;
        const render::Decimation d = render::decimate_to_budget(scene, meshes, budget);
        EXPECT_FALSE(d.fits_unsimplified);
        EXPECT_LE(std::fabs(d.relative_error()), 0.05)
            << "hash 2^" << log2 << ": " << d.bytes << " bytes for a budget of " << budget << " ("
            << d.triangles << " triangles)";
        EXPECT_EQ(d.bytes, render::mesh_gpu_bytes(d.scene.meshes[0]));
        EXPECT_EQ(d.triangles, d.scene.meshes[0].triangle_count());
        EXPECT_LT(d.triangles, d.source_triangles);
        EXPECT_EQ(d.source_bytes, full);
    }
    // A budget the full mesh fits: nothing simplified.
    const render::Decimation same = render::decimate_to_budget(scene, meshes, full * 2);
    EXPECT_TRUE(same.fits_unsimplified);
    EXPECT_EQ(same.triangles, same.source_triangles);
}

TEST(GpuMemory, MeshBytesCountVerticesTrianglesAndBlas) {
    const Mesh m = sphere(4, 8);
    const MeshBvh blas = build_mesh_bvh(m);
    EXPECT_EQ(render::mesh_gpu_bytes(m),
              m.positions.size() * 56 + m.triangle_count() * 16 + to_wide_layout(blas.bvh).size() * 64);
}

TEST(GpuMemory, NeuralBytesPerLod) {
    const NeuralModel model = test::make_tiny_model(); // LoD 0: 5 nodes, LoD 1: 3 nodes
    const render::NeuralGpuBytes b = render::neural_gpu_bytes(model);
    ASSERT_EQ(b.lod_nodes.size(), 2u);
    EXPECT_EQ(b.nodes, b.lod_nodes[0] + b.lod_nodes[1]);
    EXPECT_GT(b.lod_nodes[0], b.lod_nodes[1]);
    EXPECT_EQ(b.grid, model.grid.size() * 2);
    EXPECT_EQ(b.mlp, b.mlp_transposed);
    EXPECT_EQ(b.total_for_lod(1), b.total() - b.lod_nodes[0]);
    EXPECT_GT(b.total(), model_gpu_bytes(model)); // the file-level estimate misses buffers
}

} // namespace
