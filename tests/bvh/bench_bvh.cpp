// BVH build and traversal throughput on a random triangle soup (not a test; prints ratios/timings).
// Usage: nbvh_bench_bvh [triangles=1000000] [rays=200000]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "engine/bvh/mesh_bvh.h"
#include "engine/bvh/traverse.h"

using namespace nbvh;

int main(int argc, char** argv) {
    const uint32_t tris = argc > 1 ? uint32_t(std::strtoul(argv[1], nullptr, 10)) : 1000000u;
    const uint32_t rays = argc > 2 ? uint32_t(std::strtoul(argv[2], nullptr, 10)) : 200000u;
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    Mesh mesh;
    const float size = 2.0f / std::cbrt(float(std::max(tris, 1u)));
    for (uint32_t i = 0; i < tris; ++i) {
        glm::vec3 c(u(rng), u(rng), u(rng));
        for (int k = 0; k < 3; ++k) {
            mesh.indices.push_back(uint32_t(mesh.positions.size()));
            mesh.positions.push_back(c + size * glm::vec3(u(rng), u(rng), u(rng)));
        }
    }
    using clock = std::chrono::steady_clock;
    auto t0 = clock::now();
    MeshBvh bvh = build_mesh_bvh(mesh);
    auto t1 = clock::now();
    uint32_t hits = 0;
    for (uint32_t i = 0; i < rays; ++i) {
        glm::vec3 o = 3.0f * glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + 1e-3f);
        Ray r{o, glm::vec3(u(rng), u(rng), u(rng)) * 0.5f - o};
        Hit h;
        hits += intersect_closest(bvh, r, 0.0f, NB_INF, h);
    }
    auto t2 = clock::now();
    double build_s = std::chrono::duration<double>(t1 - t0).count();
    double trace_s = std::chrono::duration<double>(t2 - t1).count();
    std::printf("triangles %u: build %.3f s (%.2f Mtris/s), %zu nodes, depth %u\n", tris, build_s,
                tris / build_s * 1e-6, bvh.bvh.nodes.size(), bvh.bvh.max_depth());
    std::printf("rays %u: %.3f s (%.2f Mrays/s), %u hits\n", rays, trace_s, rays / trace_s * 1e-6, hits);
    return 0;
}
