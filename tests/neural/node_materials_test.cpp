// Per-node metallic and roughness (engine/neural/node_materials.h): each N-BVH node gets the
// area-weighted mean of factor x metallic-roughness texture over the triangles of its base subtree,
// and a ridge-regularised linear fit of it in the learned albedo. Two quads far apart read different
// texels (left: metallic 0, roughness 1, white base colour; right: metallic 1, roughness 0, yellow)
// under a material with metallic factor 0.5: the leaf over each quad gets its own material, the root
// their mean, nodes without a base node their parent's; the asset-wide mean (asset_shading) agrees
// with the root; the root's fit gives each quad its own material from its albedo.
#include <gtest/gtest.h>

#include "engine/bvh/mesh_bvh.h"
#include "engine/neural/asset_table.h"
#include "engine/neural/fp16.h"
#include "engine/neural/node_materials.h"
#include "shaders/shared/neural_gpu.h"
#include "shaders/shared/sampling.h"

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
    t.rgba8 = {255, 255, 255, 255, /* texel 1 */ 255, 204, 0, 255}; // sRGB white, yellow
    q.scene.textures.push_back(t);
    Material m;
    m.metallic = 0.5f;
    m.roughness = 1.0f;
    m.metallic_roughness_tex.texture = 0;
    m.base_color_tex.texture = 1;
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

// (metallic, roughness) of word group `node` of a fit table at `albedo` (as the shade pass evaluates it).
glm::vec2 eval_fit(const std::vector<uint32_t>& fits, uint32_t node, glm::vec3 albedo) {
    auto half2 = [&](uint32_t k) {
        const uint32_t w = fits[node * NB_NODE_FIT_WORDS + k];
        return glm::vec2(half_bits_to_float(uint16_t(w)), half_bits_to_float(uint16_t(w >> 16)));
    };
    return nb_node_fit_eval(half2(0), half2(1), half2(2), half2(3), albedo);
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
    const std::vector<uint32_t> w = build_node_materials(nodes, b, q.scene.meshes[0], q.scene).means;
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
    const std::vector<uint32_t> w = build_node_materials(nodes, b, q.scene.meshes[0], q.scene).means;
    ASSERT_EQ(w.size(), 3u);
    for (uint32_t x : w) EXPECT_EQ(x, nb_pack_node_material(0.5f, 1.0f));
    // Out-of-range values and NaN pack to the unit range.
    EXPECT_EQ(nb_pack_node_material(-1.0f, 2.0f), 0xFFFF0000u);
    EXPECT_EQ(nb_pack_node_material(NAN, NAN), 0u);
    EXPECT_EQ(nb_pack_node_material(1.0f, 0.0f), 0x0000FFFFu);
    // No node with a base node (an imported official tree): no table.
    const NodeMaterialTables none = build_node_materials(std::vector<NbvhNode>{node(BVH_INVALID)}, b, q.scene.meshes[0], q.scene);
    EXPECT_TRUE(none.means.empty() && none.fits.empty());
}

TEST(NodeMaterials, FitsGiveEachAlbedoItsOwnMaterial) {
    const TwoQuads q = two_quads();
    const Bvh& b = q.bvh.bvh;
    const bool left_first = b.nodes[b.nodes[0].left].bounds.lo.x < 0.0f;
    const uint32_t left_quad = left_first ? b.nodes[0].left : b.nodes[0].right;
    const uint32_t right_quad = left_first ? b.nodes[0].right : b.nodes[0].left;
    const std::vector<NbvhNode> nodes = {node(0, 1), node(left_quad), node(right_quad)};
    const NodeMaterialTables t = build_node_materials(nodes, b, q.scene.meshes[0], q.scene);
    ASSERT_EQ(t.fits.size(), nodes.size() * NB_NODE_FIT_WORDS);
    const glm::vec3 white(1.0f), yellow(1.0f, nb_srgb_to_linear(204.0f / 255.0f), 0.0f);
    // The root blends the two quads in its mean (0.25, 0.5); its fit separates them by their albedo,
    // up to the ridge's pull towards the mean (albedo variance 0.5 per axis pair vs ridge 1e-3).
    for (const auto& [albedo, want] : {std::pair{white, glm::vec2(0.0f, 1.0f)}, std::pair{yellow, glm::vec2(0.5f, 0.0f)}}) {
        const glm::vec2 got = eval_fit(t.fits, 0, albedo);
        EXPECT_NEAR(got.x, want.x, 0.01f);
        EXPECT_NEAR(got.y, want.y, 0.01f);
    }
    // A leaf of one albedo: no slope, its mean (exact up to fp16) at any albedo.
    for (glm::vec3 albedo : {white, yellow, glm::vec3(0.0f)}) {
        EXPECT_NEAR(eval_fit(t.fits, 1, albedo).x, 0.0f, 1e-3f);
        EXPECT_NEAR(eval_fit(t.fits, 1, albedo).y, 1.0f, 1e-3f);
        EXPECT_NEAR(eval_fit(t.fits, 2, albedo).x, 0.5f, 1e-3f);
        EXPECT_NEAR(eval_fit(t.fits, 2, albedo).y, 0.0f, 1e-3f);
    }
}

// Hard cases of the fit: one albedo everywhere (a singular system without the ridge: slopes 0, the
// mean), albedos a hair apart (the ridge keeps the slopes small and finite), a degenerate quad (its
// node inherits the parent's fit), and no texture at all (the factors).
TEST(NodeMaterials, FitsStayFiniteOnDegenerateAlbedos) {
    TwoQuads q = two_quads();
    const Bvh& b = q.bvh.bvh;
    const std::vector<NbvhNode> nodes = {node(0, 1), node(b.nodes[0].left), node(b.nodes[0].right)};
    q.scene.textures[1].rgba8 = {128, 128, 128, 255, 128, 128, 129, 255}; // albedos 1/255 apart (sRGB)
    NodeMaterialTables t = build_node_materials(nodes, b, q.scene.meshes[0], q.scene);
    for (uint32_t w : t.fits)
        for (float h : {half_bits_to_float(uint16_t(w)), half_bits_to_float(uint16_t(w >> 16))}) {
            EXPECT_TRUE(std::isfinite(h));
            EXPECT_LT(std::abs(h), 100.0f);
        }
    const glm::vec3 grey(nb_srgb_to_linear(128.0f / 255.0f));
    EXPECT_NEAR(eval_fit(t.fits, 0, grey).x, 0.25f, 0.02f); // too close to tell apart: about the mean
    EXPECT_NEAR(eval_fit(t.fits, 0, grey).y, 0.5f, 0.02f);
    q.scene.textures[1].rgba8 = {128, 128, 128, 255, 128, 128, 128, 255}; // one albedo
    t = build_node_materials(nodes, b, q.scene.meshes[0], q.scene);
    for (glm::vec3 albedo : {grey, glm::vec3(1.0f), glm::vec3(0.0f)}) {
        EXPECT_NEAR(eval_fit(t.fits, 0, albedo).x, 0.25f, 1e-3f);
        EXPECT_NEAR(eval_fit(t.fits, 0, albedo).y, 0.5f, 1e-3f);
    }
    q.scene.materials[0].metallic_roughness_tex.texture = -1;
    q.scene.materials[0].base_color_tex.texture = -1;
    for (uint32_t v = 4; v < 8; ++v) q.scene.meshes[0].positions[v] = q.scene.meshes[0].positions[4];
    t = build_node_materials(nodes, b, q.scene.meshes[0], q.scene);
    for (uint32_t n = 0; n < 3; ++n) {
        EXPECT_NEAR(eval_fit(t.fits, n, glm::vec3(0.3f)).x, 0.5f, 1e-3f) << n;
        EXPECT_NEAR(eval_fit(t.fits, n, glm::vec3(0.3f)).y, 1.0f, 1e-3f) << n;
    }
    // A non-finite factor (a hostile file): the defaults, never a NaN word (the reader would refuse
    // the model the trainer just wrote).
    q.scene.materials[0].metallic = NAN;
    t = build_node_materials(nodes, b, q.scene.meshes[0], q.scene);
    for (uint32_t n = 0; n < 3; ++n) {
        EXPECT_EQ(eval_fit(t.fits, n, glm::vec3(0.3f)).x, 0.0f) << n;
        EXPECT_NEAR(eval_fit(t.fits, n, glm::vec3(0.3f)).y, 1.0f, 1e-3f) << n;
    }
}

// The subtree sums over a deeper base BVH (one triangle per leaf, 3 levels): every base node as an
// N-BVH node, its mean against a brute-force sum over the triangles under it (the iterative post-order
// of node_materials.cpp must add each child exactly once).
TEST(NodeMaterials, EveryBaseNodeSumsExactlyItsSubtree) {
    TwoQuads q = two_quads();
    BvhBuildOptions o;
    o.max_leaf_size = 1;
    q.bvh = build_mesh_bvh(q.scene.meshes[0], o);
    const Bvh& b = q.bvh.bvh;
    ASSERT_EQ(b.nodes.size(), 7u);
    std::vector<NbvhNode> nodes;
    for (uint32_t i = 0; i < b.nodes.size(); ++i) nodes.push_back(node(i));
    const NodeMaterialTables t = build_node_materials(nodes, b, q.scene.meshes[0], q.scene);
    ASSERT_EQ(t.means.size(), nodes.size());
    for (uint32_t i = 0; i < b.nodes.size(); ++i) {
        double area = 0.0, metallic = 0.0, roughness = 0.0;
        std::vector<uint32_t> stack{i};
        while (!stack.empty()) {
            const BvhNode& n = b.nodes[stack.back()];
            stack.pop_back();
            if (!n.is_leaf()) {
                stack.insert(stack.end(), {n.left, n.right});
                continue;
            }
            for (uint32_t k = n.first; k < n.first + n.count; ++k) {
                MaterialPoint p[MATERIAL_POINTS];
                const double a = triangle_material_points(q.scene, q.scene.meshes[0], q.scene.materials[0], b.prim_indices[k], p);
                area += a;
                for (const MaterialPoint& x : p) {
                    metallic += a / MATERIAL_POINTS * x.metallic * 0.5; // metallic factor 0.5
                    roughness += a / MATERIAL_POINTS * x.roughness;
                }
            }
        }
        ASSERT_GT(area, 0.0);
        EXPECT_EQ(t.means[i], nb_pack_node_material(float(metallic / area), float(roughness / area))) << "base node " << i;
    }
}

// What the fit leaves: one albedo for both quads (no slope can tell them apart), so the root's fit is
// the mean (0.25, 0.5) and its spread the two quads' deviations, metallic +-0.25 against roughness -+0.5
// (anti-correlated: s_r negative): the two signs give back each quad's material exactly. A leaf of one
// material has no spread.
TEST(NodeMaterials, SpreadGivesBackWhatTheFitCannotTellApart) {
    TwoQuads q = two_quads();
    q.scene.textures[1].rgba8 = {200, 200, 200, 255, 200, 200, 200, 255};
    const Bvh& b = q.bvh.bvh;
    const bool left_first = b.nodes[b.nodes[0].left].bounds.lo.x < 0.0f;
    const uint32_t left_quad = left_first ? b.nodes[0].left : b.nodes[0].right;
    const uint32_t right_quad = left_first ? b.nodes[0].right : b.nodes[0].left;
    const std::vector<NbvhNode> nodes = {node(0, 1), node(left_quad), node(right_quad, 3), node(BVH_INVALID),
                                         node(BVH_INVALID)};
    const NodeMaterialTables t = build_node_materials(nodes, b, q.scene.meshes[0], q.scene);
    auto spread = [&](uint32_t n) {
        const uint32_t w = t.fits[n * NB_NODE_FIT_WORDS + 4];
        return glm::vec2(half_bits_to_float(uint16_t(w)), half_bits_to_float(uint16_t(w >> 16)));
    };
    const glm::vec3 grey(nb_srgb_to_linear(200.0f / 255.0f));
    const glm::vec2 fit = eval_fit(t.fits, 0, grey);
    EXPECT_NEAR(spread(0).x, 0.25f, 1e-3f);
    EXPECT_NEAR(spread(0).y, -0.5f, 1e-3f);
    const glm::vec2 minus = nb_node_fit_spread(fit, spread(0), 0u), plus = nb_node_fit_spread(fit, spread(0), 1u);
    EXPECT_NEAR(minus.x, 0.0f, 2e-3f); // the left quad: metallic 0, roughness 1
    EXPECT_NEAR(minus.y, 1.0f, 2e-3f);
    EXPECT_NEAR(plus.x, 0.5f, 2e-3f); // the right quad: metallic 0.5 (factor), roughness 0
    EXPECT_NEAR(plus.y, 0.0f, 2e-3f);
    for (uint32_t n : {1u, 2u, 3u}) { // leaves of one material, and a node inheriting from one
        EXPECT_NEAR(spread(n).x, 0.0f, 1e-3f) << n;
        EXPECT_NEAR(spread(n).y, 0.0f, 1e-3f) << n;
    }
}
