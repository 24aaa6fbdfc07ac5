#include "trainer/ground_truth.h"

#include <algorithm>
#include <cmath>

#include "engine/core/error.h"
#include "shaders/shared/intersect.h"
#include "shaders/shared/scene_gpu.h"
#include "engine/neural/asset_table.h"
#include "engine/scene/texture_sampler.h"

namespace nbvh {

namespace {

// Base-colour uv of a hit (the uv set the material's base-colour texture names); false without uvs.
bool base_color_uv(const Mesh& m, const Material* material, uint32_t tri, float u, float v, glm::vec2& uv) {
    const uint32_t uv_set = material ? material->base_color_tex.uv_set : 0u;
    const std::vector<glm::vec2>& uvs = uv_set == 1u ? m.uv1 : m.uv0;
    if (uvs.size() != m.positions.size()) return false;
    const uint32_t* idx = &m.indices[size_t(tri) * 3];
    uv = (1.0f - u - v) * uvs[idx[0]] + u * uvs[idx[1]] + v * uvs[idx[2]];
    return true;
}

const Material* material_of(const TrainingAsset& asset, uint32_t tri) {
    const Mesh& m = *asset.mesh;
    const uint32_t mat = tri < m.triangle_material.size() ? m.triangle_material[tri] : 0u;
    return mat < asset.scene->materials.size() ? &asset.scene->materials[mat] : nullptr;
}

} // namespace

bool alpha_covers(const TrainingAsset& asset, uint32_t tri, float u, float v, const SampleSlot& key) {
    const Material* material = material_of(asset, tri);
    if (!material || material->alpha_mode == AlphaMode::opaque) return true;
    float alpha = material->base_color.w;
    glm::vec2 uv;
    if (material->base_color_tex.texture >= 0 && base_color_uv(*asset.mesh, material, tri, u, v, uv))
        alpha *= sample_texture_ref(asset.scene->textures, material->base_color_tex, uv, true, glm::vec4(1.0f)).w;
    return nb_alpha_covers(uint32_t(material->alpha_mode), alpha, material->alpha_cutoff, key.coverage_bits(tri));
}

bool closest_triangle_hit(const TrainingAsset& asset, const glm::vec3& origin, const glm::vec3& dir, float tmin,
                          float tmax, const SampleSlot& key, float& t, uint32_t& triangle, float& u, float& v) {
    Hit hit;
    const HitFilter accept = [&](uint32_t tri, float hu, float hv) { return alpha_covers(asset, tri, hu, hv, key); };
    if (!intersect_closest(asset.mesh_bvh, Ray{origin, dir}, tmin, tmax, hit, asset.alpha_tested ? &accept : nullptr))
        return false;
    t = hit.t;
    triangle = hit.triangle;
    u = hit.u;
    v = hit.v;
    return true;
}

namespace {

glm::vec3 shading_normal(const TrainingAsset& asset, uint32_t tri, float u, float v, const glm::vec2& uv,
                         bool has_uv) {
    const Mesh& m = *asset.mesh;
    const uint32_t* idx = &m.indices[size_t(tri) * 3];
    const float w = 1.0f - u - v;
    glm::vec3 n(0.0f);
    if (m.normals.size() == m.positions.size()) n = w * m.normals[idx[0]] + u * m.normals[idx[1]] + v * m.normals[idx[2]];
    const glm::vec3 p0 = m.positions[idx[0]], p1 = m.positions[idx[1]], p2 = m.positions[idx[2]];
    glm::vec3 geometric = glm::cross(p1 - p0, p2 - p0);
    const float gl = glm::length(geometric);
    geometric = gl > 0.0f && std::isfinite(gl) ? geometric / gl : glm::vec3(0.0f, 0.0f, 1.0f);
    float nl = glm::length(n);
    if (!(nl > 1e-12f) || !std::isfinite(nl)) return geometric;
    n /= nl;
    // Normal map (glTF tangent space) when the material has one and the mesh has tangents.
    const uint32_t mat = tri < m.triangle_material.size() ? m.triangle_material[tri] : 0u;
    const Scene& scene = *asset.scene;
    if (has_uv && mat < scene.materials.size() && scene.materials[mat].normal_tex.texture >= 0 &&
        m.tangents.size() == m.positions.size()) {
        const Material& material = scene.materials[mat];
        const glm::vec4 t4 = w * m.tangents[idx[0]] + u * m.tangents[idx[1]] + v * m.tangents[idx[2]];
        glm::vec3 t = glm::vec3(t4) - n * glm::dot(n, glm::vec3(t4));
        const float tl = glm::length(t);
        if (tl > 1e-12f && std::isfinite(tl)) {
            t /= tl;
            const glm::vec3 b = glm::cross(n, t) * (t4.w < 0.0f ? -1.0f : 1.0f);
            const glm::vec4 tex = sample_texture_ref(scene.textures, material.normal_tex, uv, false, glm::vec4(0.5f, 0.5f, 1.0f, 1.0f));
            glm::vec3 tn = glm::vec3(tex) * 2.0f - 1.0f;
            tn.x *= material.normal_scale;
            tn.y *= material.normal_scale;
            const glm::vec3 mapped = tn.x * t + tn.y * b + tn.z * n;
            const float ml = glm::length(mapped);
            if (ml > 1e-12f && std::isfinite(ml)) n = mapped / ml;
        }
    }
    return n;
}

} // namespace

GroundTruth trace_ground_truth(const TrainingAsset& asset, const glm::vec3& origin, const glm::vec3& dir,
                               float t_entry, float t_exit, const SampleSlot& key) {
    GroundTruth gt;
    float t, u, v;
    uint32_t tri;
    if (!closest_triangle_hit(asset, origin, dir, t_entry, t_exit, key, t, tri, u, v)) return gt;
    gt.hit = true;
    gt.t_hit = t;
    gt.triangle = tri;
    gt.depth = nb_encode_depth_target(asset.encoding, t, t_entry, t_exit, false);

    const Material* material = material_of(asset, tri);
    glm::vec2 uv(0.0f);
    const bool has_uv = base_color_uv(*asset.mesh, material, tri, u, v, uv);
    gt.normal = shading_normal(asset, tri, u, v, uv, has_uv);
    gt.albedo = learned_albedo(*asset.scene, material, uv, has_uv);
    return gt;
}

} // namespace nbvh
