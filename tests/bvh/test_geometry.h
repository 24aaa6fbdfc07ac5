// Random and degenerate triangle sets for the BVH tests.
#pragma once
#include <random>

#include "engine/bvh/traverse.h"
#include "engine/scene/scene.h"

namespace nbvh::test {

inline Mesh make_mesh(const std::vector<glm::vec3>& tri_vertices) {
    Mesh m;
    m.positions = tri_vertices;
    for (uint32_t i = 0; i < tri_vertices.size(); ++i) m.indices.push_back(i);
    m.triangle_material.assign(tri_vertices.size() / 3, 0);
    return m;
}

// `n` random triangles of size about `size` in the box [offset - scale, offset + scale]^3.
inline std::vector<glm::vec3> random_soup(std::mt19937& rng, uint32_t n, float scale, float size,
                                          glm::vec3 offset = glm::vec3(0.0f)) {
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::vector<glm::vec3> v;
    for (uint32_t i = 0; i < n; ++i) {
        glm::vec3 c = offset + scale * glm::vec3(u(rng), u(rng), u(rng));
        for (int k = 0; k < 3; ++k) v.push_back(c + size * glm::vec3(u(rng), u(rng), u(rng)));
    }
    return v;
}

// A ray from a random point on a sphere around `center` towards a random point near it.
inline Ray random_ray(std::mt19937& rng, glm::vec3 center, float radius) {
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    glm::vec3 o = center + 2.0f * radius * glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + 1e-3f);
    glm::vec3 target = center + radius * glm::vec3(u(rng), u(rng), u(rng));
    return Ray{o, target - o};
}

} // namespace nbvh::test
