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

// uv of a hit in uv set `set` (0 or 1, a texture reference's); false when the mesh has no such uvs.
bool hit_uv(const Mesh& m, uint32_t set, uint32_t tri, float u, float v, glm::vec2& uv) {
    const std::vector<glm::vec2>& uvs = set == 1u ? m.uv1 : m.uv0;
    if (uvs.size() != m.positions.size()) return false;
    const uint32_t* idx = &m.indices[size_t(tri) * 3];
    uv = (1.0f - u - v) * uvs[idx[0]] + u * uvs[idx[1]] + v * uvs[idx[2]];
    return true;
}

// Base-colour uv of a hit (the uv set the material's base-colour texture names).
bool base_color_uv(const Mesh& m, const Material* material, uint32_t tri, float u, float v, glm::vec2& uv) {
    return hit_uv(m, material ? material->base_color_tex.uv_set : 0u, tri, u, v, uv);
}

const Material* material_of(const TrainingAsset& asset, uint32_t tri) {
    const Mesh& m = *asset.mesh;
    const uint32_t mat = tri < m.triangle_material.size() ? m.triangle_material[tri] : 0u;
    return mat < asset.scene->materials.size() ? &asset.scene->materials[mat] : nullptr;
}

glm::vec3 shading_normal(const TrainingAsset& asset, const Material* material, uint32_t tri, float u, float v) {
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
    // Normal map (glTF tangent space, its own uv set) when the material has one and the mesh has tangents.
    glm::vec2 uv;
    if (material && material->normal_tex.texture >= 0 && m.tangents.size() == m.positions.size() &&
        hit_uv(m, material->normal_tex.uv_set, tri, u, v, uv)) {
        const glm::vec4 t4 = w * m.tangents[idx[0]] + u * m.tangents[idx[1]] + v * m.tangents[idx[2]];
        const glm::vec4 tex = sample_texture_ref(asset.scene->textures, material->normal_tex, uv, false,
                                                 glm::vec4(0.5f, 0.5f, 1.0f, 1.0f));
        n = nb_normal_map(n, t4, glm::vec3(tex), material->normal_scale);
    }
    return n;
}

// Alpha of a hit: base-colour factor x texture alpha.
float surface_alpha(const TrainingAsset& asset, const Material& material, uint32_t tri, float u, float v) {
    float alpha = material.base_color.w;
    glm::vec2 uv;
    if (material.base_color_tex.texture >= 0 && base_color_uv(*asset.mesh, &material, tri, u, v, uv))
        alpha *= sample_texture_ref(asset.scene->textures, material.base_color_tex, uv, true, glm::vec4(1.0f)).w;
    return alpha;
}

// A back face of a single-sided blended triangle: rays pass it (the classical traversal's rule).
bool blended_back_face(const TrainingAsset& asset, const Material& material, uint32_t tri, const glm::vec3& dir) {
    if (material.alpha_mode != AlphaMode::blend || material.double_sided) return false;
    const Mesh& m = *asset.mesh;
    const uint32_t* idx = &m.indices[size_t(tri) * 3];
    return nb_back_facing(m.positions[idx[0]], m.positions[idx[1]], m.positions[idx[2]], dir);
}

// Whether a hit at barycentrics (u, v) of triangle `tri` (original index, its `material`), on a ray
// along `dir`, counts (ground_truth.h).
bool alpha_covers(const TrainingAsset& asset, const Material* material, uint32_t tri, float u, float v,
                  const glm::vec3& dir, const SampleSlot& key) {
    if (!material || material->alpha_mode == AlphaMode::opaque) return true;
    if (blended_back_face(asset, *material, tri, dir)) return false;
    return nb_alpha_covers(uint32_t(material->alpha_mode), surface_alpha(asset, *material, tri, u, v),
                           material->alpha_cutoff, key.coverage_bits(tri));
}

} // namespace

StopProbability stop_probability(const TrainingAsset& asset, const glm::vec3& origin, const glm::vec3& dir,
                                 float tmin, float tmax) {
    StopProbability s;
    float pass = 1.0f;
    bool solid = false;
    const HitFilter visit = [&](uint32_t tri, float t, float u, float v) {
        const Material* material = material_of(asset, tri);
        if (!material || material->alpha_mode == AlphaMode::opaque) {
            solid = true;
            return true; // nothing behind it matters
        }
        if (blended_back_face(asset, *material, tri, dir)) return false;
        const float alpha = surface_alpha(asset, *material, tri, u, v);
        if (material->alpha_mode == AlphaMode::mask) { // the shared rule; a MASK test draws nothing
            const bool kept = nb_alpha_covers(NB_ALPHA_MASK, alpha, material->alpha_cutoff, 0u);
            solid = solid || kept;
            return kept;
        }
        pass *= 1.0f - (std::isfinite(alpha) ? std::clamp(alpha, 0.0f, 1.0f) : 0.0f);
        if (t < s.nearest_t) s = StopProbability{0.0f, t, tri, u, v};
        return false; // every blended crossing counts
    };
    Hit hit;
    intersect_closest(asset.mesh_bvh, Ray{origin, dir}, tmin, tmax, hit, &visit);
    s.probability = solid ? 1.0f : 1.0f - pass;
    return s;
}

bool closest_triangle_hit(const TrainingAsset& asset, const glm::vec3& origin, const glm::vec3& dir, float tmin,
                          float tmax, const SampleSlot& key, float& t, uint32_t& triangle, float& u, float& v,
                          bool* blended) {
    Hit hit;
    bool hit_blended = false, met_blended = false;
    const HitFilter accept = [&](uint32_t tri, float, float hu, float hv) {
        const Material* material = material_of(asset, tri);
        const bool blend = material && material->alpha_mode == AlphaMode::blend;
        met_blended = met_blended || blend;
        if (!alpha_covers(asset, material, tri, hu, hv, dir, key)) return false;
        hit_blended = blend;
        return true;
    };
    const bool found =
        intersect_closest(asset.mesh_bvh, Ray{origin, dir}, tmin, tmax, hit, asset.alpha_tested ? &accept : nullptr);
    if (blended) *blended = found ? hit_blended : met_blended;
    if (!found) return false;
    t = hit.t;
    triangle = hit.triangle;
    u = hit.u;
    v = hit.v;
    return true;
}

GroundTruth trace_ground_truth(const TrainingAsset& asset, const glm::vec3& origin, const glm::vec3& dir,
                               float t_entry, float t_exit, const SampleSlot& key) {
    GroundTruth gt;
    float t = 0.0f, u = 0.0f, v = 0.0f;
    uint32_t tri = 0;
    bool blended = false;
    const bool drawn = closest_triangle_hit(asset, origin, dir, t_entry, t_exit, key, t, tri, u, v, &blended);
    gt.visibility = drawn ? 1.0f : 0.0f;
    if (asset.alpha_tested && blended) {
        // Visibility target: the probability that the segment stops the ray, not the draw's 0 or 1; the
        // surface: the draw's, else (the draws let the ray through) the nearest blended crossing. (Only
        // where a blended surface was met: else it is 1 with a hit, 0 without.)
        const StopProbability s = stop_probability(asset, origin, dir, t_entry, t_exit);
        gt.visibility = s.probability;
        if (!drawn) {
            t = s.nearest_t;
            tri = s.triangle;
            u = s.u;
            v = s.v;
        }
    }
    if (!(gt.visibility > 0.0f)) return GroundTruth{};
    gt.hit = true;
    gt.t_hit = t;
    gt.triangle = tri;
    gt.depth = nb_encode_depth_target(asset.encoding, t, t_entry, t_exit, false);

    const Material* material = material_of(asset, tri);
    glm::vec2 uv(0.0f);
    const bool has_uv = base_color_uv(*asset.mesh, material, tri, u, v, uv);
    gt.normal = shading_normal(asset, material, tri, u, v);
    gt.albedo = learned_albedo(*asset.scene, material, uv, has_uv);
    return gt;
}

} // namespace nbvh
