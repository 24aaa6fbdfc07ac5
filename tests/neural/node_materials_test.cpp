// Per-node metallic and roughness (engine/neural/node_materials.h): each N-BVH node gets the
// area-weighted mean of factor x metallic-roughness texture over the triangles of its base subtree.
// Two quads far apart read different texels (left: metallic 0, roughness 1; right: metallic 1,
// roughness 0) under a material with metallic factor 0.5: the leaf over each quad gets its own
// material, the root their mean, nodes without a base node their parent's; the asset-wide mean
// (asset_shading) agrees with the root.
#include <gtest/gtest.h>

#include "engine/bvh/mesh_bvh.h"
#include "engine/neural/asset_table.h"
#include "engine/neural/node_materials.h"
#include "shaders/shared/neural_gpu.h"

using namespace nbvh;

namespace {

struct TwoQuads {
    Scene scene;
    MeshBvh bvh;
};

TwoQuads two_quads() {
    TwoQuads q;
    Texture t;
    t.width = 2;
    t.height = 1;
    t.rgba8 = {0, 255, 0, 255, /* texel 1 */ 0, 0, 255, 255}; // G = roughness, B = metallic
    q.scene.textures.push_back(t);
    Material m;
    m.metallic = 0.5f;
    m.roughness = 1.0f;
    m.metallic_roughness_tex.texture = 0;
    q.scene.materials.push_back(m);
    Mesh mesh;
    mesh.name = "quads";
    for (float x0 : {-2.0f, 1.0f}) {
        const uint32_t b = uint32_t(mesh.positions.size());
        for (glm::vec2 c : {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(1, 1), glm::vec2(0, 1)}) {
            mesh.positions.push_back({x0 + c.x, c.y, 0.0f});
            mesh.uv0.push_back({x0 < 0.0f ? 0.25f : 0.75f, 0.5f}); // the texel centres
        }
        for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) mesh.indices.push_back(b + i);
    }
    mesh.triangle_material.assign(4, 0u);
    q.scene.meshes.push_back(mesh);
    BvhBuildOptions o;
    o.max_leaf_size = 2;
    q.bvh = build_mesh_bvh(q.scene.meshes[0], o);
    return q;
}

NbvhNode node(uint32_t base, uint32_t left = NBVH_NO_CHILD) {
    NbvhNode n;
    n.base_node = base;
    n.left = left;
    return n;
}

} // namespace

TEST(NodeMaterials, EachNodeAveragesItsOwnTriangles) {
    const TwoQuads q = two_quads();
    const Bvh& b = q.bvh.bvh;
    ASSERT_FALSE(b.nodes[0].is_leaf());
    const bool left_first = b.nodes[b.nodes[0].left].bounds.lo.x < 0.0f;
    const uint32_t left_quad = left_first ? b.nodes[0].left : b.nodes[0].right;
    const uint32_t right_quad = left_first ? b.nodes[0].right : b.nodes[0].left;
    ASSERT_TRUE(b.nodes[left_quad].is_leaf() && b.nodes[right_quad].is_leaf());
    // Root, the two quads, and under the right quad two nodes without a base node.
    const std::vector<NbvhNode> nodes = {node(0, 1), node(left_quad), node(right_quad, 3), node(BVH_INVALID),
                                         node(BVH_INVALID)};
    const std::vector<uint32_t> w = build_node_materials(nodes, b, q.scene.meshes[0], q.scene);
    ASSERT_EQ(w.size(), nodes.size());
    EXPECT_EQ(w[0], nb_pack_node_material(0.25f, 0.5f));
    EXPECT_EQ(w[1], nb_pack_node_material(0.0f, 1.0f));
    EXPECT_EQ(w[2], nb_pack_node_material(0.5f, 0.0f));
    EXPECT_EQ(w[3], w[2]);
    EXPECT_EQ(w[4], w[2]);
    const AssetShading s = asset_shading(q.scene, 0);
    EXPECT_FLOAT_EQ(s.metallic, 0.25f);
    EXPECT_FLOAT_EQ(s.roughness, 0.5f);
}

TEST(NodeMaterials, DegenerateInputsFallBackWithoutNaN) {
    TwoQuads q = two_quads();
    // Without a texture: the factors; a degenerate quad inherits its parent's value.
    q.scene.materials[0].metallic_roughness_tex.texture = -1;
    for (uint32_t v = 4; v < 8; ++v) q.scene.meshes[0].positions[v] = q.scene.meshes[0].positions[4];
    const Bvh& b = q.bvh.bvh;
    const std::vector<NbvhNode> nodes = {node(0, 1), node(b.nodes[0].left), node(b.nodes[0].right)};
    const std::vector<uint32_t> w = build_node_materials(nodes, b, q.scene.meshes[0], q.scene);
    ASSERT_EQ(w.size(), 3u);
    for (uint32_t x : w) EXPECT_EQ(x, nb_pack_node_material(0.5f, 1.0f));
    // Out-of-range values and NaN pack to the unit range.
    EXPECT_EQ(nb_pack_node_material(-1.0f, 2.0f), 0xFFFF0000u);
    EXPECT_EQ(nb_pack_node_material(NAN, NAN), 0u);
    EXPECT_EQ(nb_pack_node_material(1.0f, 0.0f), 0x0000FFFFu);
    // No node with a base node (an imported official tree): no table.
    EXPECT_TRUE(build_node_materials(std::vector<NbvhNode>{node(BVH_INVALID)}, b, q.scene.meshes[0], q.scene).empty());
}
