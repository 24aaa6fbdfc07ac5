// Small synthetic neural assets for the trainer tests (built in memory, no files).
#pragma once
#include <cmath>

#include <glm/glm.hpp>

#include "engine/scene/scene.h"

namespace nbvh::test {

// A scene with one neural instance of `mesh` and one material of base colour `albedo`.
inline Scene scene_of(Mesh mesh, glm::vec3 albedo = glm::vec3(0.8f, 0.4f, 0.2f)) {
    Scene s;
    mesh.triangle_material.assign(mesh.triangle_count(), 0u);
    s.meshes.push_back(std::move(mesh));
    Material m;
    m.base_color = glm::vec4(albedo, 1.0f);
    s.materials.push_back(m);
    Instance inst;
    inst.mesh = 0;
    inst.neural = true;
    inst.name = "asset";
    s.instances.push_back(inst);
    return s;
}

inline void add_quad(Mesh& m, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, glm::vec3 n) {
    const uint32_t base = uint32_t(m.positions.size());
    for (glm::vec3 p : {a, b, c, d}) {
        m.positions.push_back(p);
        m.normals.push_back(n);
    }
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
}

// A height field z = amp * sin(x) cos(y) over [0,1]^2 in n x n quads, scaled by `scale` and moved
// by `offset`. amp = 0 gives a flat asset (zero extent along z).
inline Mesh height_field(uint32_t n, float amp, float scale, glm::vec3 offset) {
    Mesh m;
    m.name = "height_field";
    auto z = [&](float x, float y) { return amp * std::sin(6.0f * x) * std::cos(5.0f * y); };
    for (uint32_t j = 0; j <= n; ++j)
        for (uint32_t i = 0; i <= n; ++i) {
            const float x = float(i) / float(n), y = float(j) / float(n);
            m.positions.push_back(offset + scale * glm::vec3(x, y, z(x, y)));
            const glm::vec3 dx(1.0f, 0.0f, amp * 6.0f * std::cos(6.0f * x) * std::cos(5.0f * y));
            const glm::vec3 dy(0.0f, 1.0f, -amp * 5.0f * std::sin(6.0f * x) * std::sin(5.0f * y));
            m.normals.push_back(glm::normalize(glm::cross(dx, dy)));
        }
    for (uint32_t j = 0; j < n; ++j)
        for (uint32_t i = 0; i < n; ++i) {
            const uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
            for (uint32_t k : {a, b, d, a, d, c}) m.indices.push_back(k);
        }
    return m;
}

// An axis-aligned unit cube [0,1]^3 * scale + offset, 12 triangles, outward normals.
inline Mesh cube(float scale = 1.0f, glm::vec3 offset = glm::vec3(0.0f)) {
    Mesh m;
    m.name = "cube";
    auto P = [&](float x, float y, float z) { return offset + scale * glm::vec3(x, y, z); };
    add_quad(m, P(0, 0, 0), P(0, 1, 0), P(1, 1, 0), P(1, 0, 0), {0, 0, -1});
    add_quad(m, P(0, 0, 1), P(1, 0, 1), P(1, 1, 1), P(0, 1, 1), {0, 0, 1});
    add_quad(m, P(0, 0, 0), P(1, 0, 0), P(1, 0, 1), P(0, 0, 1), {0, -1, 0});
    add_quad(m, P(0, 1, 0), P(0, 1, 1), P(1, 1, 1), P(1, 1, 0), {0, 1, 0});
    add_quad(m, P(0, 0, 0), P(0, 0, 1), P(0, 1, 1), P(0, 1, 0), {-1, 0, 0});
    add_quad(m, P(1, 0, 0), P(1, 1, 0), P(1, 1, 1), P(1, 0, 1), {1, 0, 0});
    return m;
}

// A normal-mapped height field (16 x 16 quads, amplitude 0.2): uv set 1 = xy, tangents along +x
// (handedness -1 on the right half), an 8x8 normal texture of varied tilts read through a
// texture transform, normalTexture.scale 0.8. No uv set 0: the base colour is untextured.
inline Scene normal_mapped_scene() {
    Mesh m = height_field(16, 0.2f, 1.0f, glm::vec3(0.0f));
    for (const glm::vec3& p : m.positions) {
        m.uv1.push_back(glm::vec2(p.x, p.y));
        m.tangents.push_back(glm::vec4(1.0f, 0.0f, 0.0f, p.x > 0.5f ? -1.0f : 1.0f));
    }
    Scene s = scene_of(m);
    Texture t;
    t.width = t.height = 8;
    for (uint32_t i = 0; i < 64; ++i)
        t.rgba8.insert(t.rgba8.end(), {uint8_t(40 + 23 * (i % 8)), uint8_t(200 - 19 * (i / 8)), uint8_t(150 + (i * 37) % 100), 255});
    s.textures.push_back(t);
    s.materials[0].normal_tex.texture = 0;
    s.materials[0].normal_tex.uv_set = 1;
    s.materials[0].normal_tex.transform = glm::mat3(2.0f, 0.0f, 0.0f, 0.0f, 1.5f, 0.0f, 0.1f, 0.2f, 1.0f);
    s.materials[0].normal_scale = 0.8f;
    return s;
}

// Alpha-tested surfaces (glTF alphaMode) for the ground-truth tests, one mesh, rays along -z:
// - triangles 0-1, material 0 (MASK, cutoff 0.5): quad [0,1]^2 at z = 0, uv = xy, base-colour texture
//   of 2x1 texels with alpha 0 (left) and 255 (right): a hole where x < 0.5;
// - triangles 2-3, material 1 (BLEND, alpha factor 0.3): quad [1.2,2.2] x [0,1] at z = 0;
// - triangles 4-5, material 2 (opaque): a backdrop [0,2.2] x [0,1] at z = -0.5.
inline Scene alpha_quads_scene() {
    Mesh m;
    m.name = "alpha_quads";
    add_quad(m, {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1});
    add_quad(m, {1.2f, 0, 0}, {2.2f, 0, 0}, {2.2f, 1, 0}, {1.2f, 1, 0}, {0, 0, 1});
    add_quad(m, {0, 0, -0.5f}, {2.2f, 0, -0.5f}, {2.2f, 1, -0.5f}, {0, 1, -0.5f}, {0, 0, 1});
    for (size_t i = 0; i < m.positions.size(); ++i) m.uv0.push_back(glm::vec2(m.positions[i]));
    Scene s = scene_of(m);
    s.meshes[0].triangle_material = {0, 0, 1, 1, 2, 2};
    Texture t;
    t.width = 2;
    t.height = 1;
    t.rgba8 = {200, 200, 200, 0, 200, 200, 200, 255};
    t.srgb = true;
    s.textures.push_back(t);
    Material mask = s.materials[0], blend = s.materials[0], opaque = s.materials[0];
    mask.alpha_mode = AlphaMode::mask;
    mask.alpha_cutoff = 0.5f;
    mask.base_color_tex.texture = 0;
    blend.alpha_mode = AlphaMode::blend;
    blend.base_color.w = 0.3f;
    s.materials = {mask, blend, opaque};
    return s;
}

} // namespace nbvh::test
