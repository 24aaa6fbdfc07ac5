// A real scan (Stanford bunny from ../shared/scenes) against brute force. The mesh is read with
// tinygltf directly so this test depends only on the BVH library.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include <tiny_gltf.h>

#include "engine/bvh/mesh_bvh.h"
#include "test_geometry.h"
#include "tests/support/test_support.h"

namespace nbvh {
namespace {

// All TRIANGLES primitives of all meshes merged, in mesh space (node transforms are ignored).
Mesh read_glb_triangles(const std::string& path) {
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    EXPECT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, path)) << err;
    Mesh mesh;
    for (const tinygltf::Mesh& m : model.meshes) {
        for (const tinygltf::Primitive& p : m.primitives) {
            if (p.mode != TINYGLTF_MODE_TRIANGLES || !p.attributes.count("POSITION") || p.indices < 0) continue;
            const tinygltf::Accessor& pa = model.accessors[p.attributes.at("POSITION")];
            const tinygltf::BufferView& pv = model.bufferViews[pa.bufferView];
            const unsigned char* pbase = model.buffers[pv.buffer].data.data() + pv.byteOffset + pa.byteOffset;
            const size_t pstride = pv.byteStride ? pv.byteStride : 12;
            const uint32_t base = uint32_t(mesh.positions.size());
            for (size_t i = 0; i < pa.count; ++i) {
                glm::vec3 v;
                std::memcpy(&v, pbase + i * pstride, 12);
                mesh.positions.push_back(v);
            }
            const tinygltf::Accessor& ia = model.accessors[p.indices];
            const tinygltf::BufferView& iv = model.bufferViews[ia.bufferView];
            const unsigned char* ibase = model.buffers[iv.buffer].data.data() + iv.byteOffset + ia.byteOffset;
            for (size_t i = 0; i < ia.count; ++i) {
                uint32_t idx = 0;
                if (ia.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) std::memcpy(&idx, ibase + 4 * i, 4);
                else if (ia.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
                    uint16_t s;
                    std::memcpy(&s, ibase + 2 * i, 2);
                    idx = s;
                } else idx = ibase[i];
                mesh.indices.push_back(base + idx);
            }
        }
    }
    return mesh;
}

TEST(BvhRealScene, BunnyMatchesBruteForce) {
    NBVH_REQUIRE_SHARED();
    Mesh mesh = read_glb_triangles((test::scenes_dir() / "stanford_bunny" / "stanford_bunny.glb").string());
    ASSERT_GT(mesh.triangle_count(), 1000u);
    MeshBvh m = build_mesh_bvh(mesh);
    EXPECT_EQ(m.triangle_count(), mesh.triangle_count());
    EXPECT_LT(m.bvh.max_depth(), NB_BVH_MAX_DEPTH);
    Aabb b = m.bounds();
    glm::vec3 c = b.center();
    float radius = 0.5f * glm::length(b.extent());
    std::mt19937 rng(1);
    int hits = 0;
    for (int r = 0; r < 400; ++r) {
        Ray ray = test::random_ray(rng, c, radius);
        Hit h1, h2;
        bool b1 = intersect_closest(m, ray, 0.0f, NB_INF, h1);
        bool b2 = intersect_closest_brute_force(mesh, ray, 0.0f, NB_INF, h2);
        ASSERT_EQ(b1, b2) << "ray " << r;
        if (!b1) continue;
        ++hits;
        ASSERT_EQ(h1.t, h2.t);
        ASSERT_EQ(h1.triangle, h2.triangle);
        // Secondary rays leaving the surface (tmin > 0) and shadow rays towards the origin.
        Ray next{ray.org + h1.t * ray.dir, -ray.dir};
        bool n1 = intersect_closest(m, next, 1e-4f, NB_INF, h1);
        bool n2 = intersect_closest_brute_force(mesh, next, 1e-4f, NB_INF, h2);
        ASSERT_EQ(n1, n2);
        if (n1) {
            ASSERT_EQ(h1.t, h2.t);
        }
        EXPECT_EQ(intersect_any(m, next, 1e-4f, 0.99f), n2 && h2.t <= 0.99f);
    }
    EXPECT_GT(hits, 100);
}

} // namespace
} // namespace nbvh
