#include "engine/neural/asset_table.h"

#include <algorithm>
#include <map>

#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/scene/texture_sampler.h"

#include <cmath>

namespace nbvh {

namespace {

std::string material_label(const Scene& scene, uint32_t m) {
    if (m < scene.materials.size() && !scene.materials[m].name.empty()) return scene.materials[m].name;
    return strfmt("material%u", m);
}

// The part of `src` made of its triangles of material `mat` (vertices used by them, in first-use order).
Mesh cut_by_material(const Mesh& src, uint32_t mat, const std::string& name) {
    Mesh out;
    out.name = name;
    out.split_from = src.name;
    std::vector<uint32_t> remap(src.positions.size(), 0xFFFFFFFFu);
    auto vertex = [&](uint32_t v) {
        if (remap[v] == 0xFFFFFFFFu) {
            remap[v] = uint32_t(out.positions.size());
            out.positions.push_back(src.positions[v]);
            if (v < src.normals.size()) out.normals.push_back(src.normals[v]);
            if (v < src.tangents.size()) out.tangents.push_back(src.tangents[v]);
            if (v < src.uv0.size()) out.uv0.push_back(src.uv0[v]);
            if (v < src.uv1.size()) out.uv1.push_back(src.uv1[v]);
        }
        return remap[v];
    };
    for (uint32_t t = 0; t < src.triangle_count(); ++t) {
        const uint32_t m = t < src.triangle_material.size() ? src.triangle_material[t] : 0u;
        if (m != mat) continue;
        bool ok = true;
        for (int k = 0; k < 3; ++k) ok = ok && src.indices[3 * t + k] < src.positions.size();
        if (!ok) continue;
        for (int k = 0; k < 3; ++k) out.indices.push_back(vertex(src.indices[3 * t + k]));
        out.triangle_material.push_back(mat);
    }
    return out;
}

} // namespace

uint32_t split_neural_meshes(Scene& scene) {
    const size_t mesh_count = scene.meshes.size();
    std::vector<std::vector<uint32_t>> parts(mesh_count); // mesh -> its per-material meshes
    std::vector<bool> neural(mesh_count, false);
    for (const Instance& i : scene.instances)
        if (i.neural && i.mesh < mesh_count) neural[i.mesh] = true;
    uint32_t cut = 0;
    for (uint32_t m = 0; m < mesh_count; ++m) {
        if (!neural[m]) continue;
        std::vector<uint32_t> mats;
        for (uint32_t t = 0; t < scene.meshes[m].triangle_count(); ++t) {
            const auto& tm = scene.meshes[m].triangle_material;
            const uint32_t mat = t < tm.size() ? tm[t] : 0u;
            if (std::find(mats.begin(), mats.end(), mat) == mats.end()) mats.push_back(mat);
        }
        if (mats.size() < 2) continue;
        std::sort(mats.begin(), mats.end());
        for (uint32_t mat : mats) {
            Mesh part = cut_by_material(scene.meshes[m], mat, scene.meshes[m].name + "/" + material_label(scene, mat));
            if (part.indices.empty()) continue;
            parts[m].push_back(uint32_t(scene.meshes.size()));
            scene.meshes.push_back(std::move(part));
        }
        ++cut;
    }
    if (cut == 0) return 0;
    std::vector<Instance> out;
    out.reserve(scene.instances.size());
    for (const Instance& i : scene.instances) {
        if (!i.neural || i.mesh >= mesh_count || parts[i.mesh].empty()) {
            out.push_back(i);
            continue;
        }
        for (uint32_t p : parts[i.mesh]) {
            Instance c = i;
            c.mesh = p;
            out.push_back(c);
        }
    }
    scene.instances = std::move(out);
    return cut;
}

uint64_t geometry_fingerprint(const Mesh& mesh) {
    uint64_t h = fnv1a64(mesh.positions.data(), mesh.positions.size() * sizeof(glm::vec3));
    return fnv1a64(mesh.indices.data(), mesh.indices.size() * sizeof(uint32_t), h);
}

uint64_t material_fingerprint(const Scene& scene, uint32_t material) {
    if (material >= scene.materials.size()) return 0;
    const Material& m = scene.materials[material];
    uint64_t h = fnv1a64(&m.base_color, sizeof(m.base_color));
    const uint32_t alpha = uint32_t(m.alpha_mode);
    h = fnv1a64(&alpha, sizeof(alpha), h);
    const TextureRef& t = m.base_color_tex;
    if (t.texture >= 0 && size_t(t.texture) < scene.textures.size()) {
        const Texture& tex = scene.textures[size_t(t.texture)];
        h = fnv1a64(&tex.width, sizeof(tex.width), h);
        h = fnv1a64(&tex.height, sizeof(tex.height), h);
        h = fnv1a64(tex.rgba8.data(), tex.rgba8.size(), h);
        h = fnv1a64(&t.uv_set, sizeof(t.uv_set), h);
        h = fnv1a64(&t.transform, sizeof(t.transform), h);
    }
    return h == 0 ? 1 : h; // 0 means "unknown"
}

glm::vec3 learned_albedo(const Scene& scene, const Material* material, glm::vec2 uv, bool has_uv) {
    glm::vec3 albedo(0.9f);
    if (material) {
        albedo = glm::vec3(material->base_color);
        if (has_uv && material->base_color_tex.texture >= 0)
            albedo *= glm::vec3(sample_texture_ref(scene.textures, material->base_color_tex, uv, true, glm::vec4(1.0f)));
    }
    albedo = glm::clamp(albedo, glm::vec3(0.0f), glm::vec3(1.0f));
    return std::isfinite(albedo.x + albedo.y + albedo.z) ? albedo : glm::vec3(0.9f);
}

double triangle_material_points(const Scene& scene, const Mesh& m, const Material& material, uint32_t t,
                                MaterialPoint points[MATERIAL_POINTS], bool with_albedo) {
    if (3 * size_t(t) + 2 >= m.indices.size()) return 0.0;
    const uint32_t* idx = &m.indices[3 * size_t(t)];
    if (idx[0] >= m.positions.size() || idx[1] >= m.positions.size() || idx[2] >= m.positions.size()) return 0.0;
    const glm::vec3 p0 = m.positions[idx[0]], p1 = m.positions[idx[1]], p2 = m.positions[idx[2]];
    const double area = 0.5 * double(glm::length(glm::cross(p1 - p0, p2 - p0)));
    if (!(area > 0.0) || !std::isfinite(area)) return 0.0;
    static constexpr float BARY[MATERIAL_POINTS][3] = {{1.f / 3, 1.f / 3, 1.f / 3}, {2.f / 3, 1.f / 6, 1.f / 6},
                                                       {1.f / 6, 2.f / 3, 1.f / 6}, {1.f / 6, 1.f / 6, 2.f / 3}};
    auto uv_of = [&](uint32_t uv_set, const float* w, glm::vec2& uv) {
        const std::vector<glm::vec2>& uvs = uv_set == 1u ? m.uv1 : m.uv0;
        if (uvs.size() != m.positions.size()) return false;
        uv = w[0] * uvs[idx[0]] + w[1] * uvs[idx[1]] + w[2] * uvs[idx[2]];
        return true;
    };
    const TextureRef& mr = material.metallic_roughness_tex;
    const bool mr_texture = mr.texture >= 0 && size_t(mr.texture) < scene.textures.size();
    for (uint32_t k = 0; k < MATERIAL_POINTS; ++k) {
        MaterialPoint& p = points[k];
        glm::vec2 uv(0.0f);
        p.albedo = glm::vec3(0.0f);
        if (with_albedo) {
            const bool has_uv = uv_of(material.base_color_tex.uv_set, BARY[k], uv);
            p.albedo = learned_albedo(scene, &material, uv, has_uv);
        }
        p.metallic = p.roughness = 1.0f;
        if (mr_texture && uv_of(mr.uv_set, BARY[k], uv)) {
            const glm::vec4 c = sample_texture_ref(scene.textures, mr, uv, false, glm::vec4(1.0f));
            p.metallic = c.b;
            p.roughness = c.g;
        }
    }
    return area;
}

AssetShading asset_shading(const Scene& scene, uint32_t mesh) {
    NBVH_CHECK(mesh < scene.meshes.size());
    const Mesh& m = scene.meshes[mesh];
    const uint32_t mat = m.triangle_material.empty() ? 0u : m.triangle_material[0];
    AssetShading s;
    if (mat >= scene.materials.size()) return s;
    const Material& material = scene.materials[mat];
    s.metallic = std::clamp(material.metallic, 0.0f, 1.0f);
    s.roughness = std::clamp(material.roughness, 0.0f, 1.0f);
    s.transmission = std::clamp(material.transmission, 0.0f, 1.0f);
    const TextureRef& ref = material.metallic_roughness_tex;
    const std::vector<glm::vec2>& uvs = ref.uv_set == 1u ? m.uv1 : m.uv0;
    if (ref.texture < 0 || size_t(ref.texture) >= scene.textures.size() || uvs.size() != m.positions.size()) return s;
    double area = 0.0, metallic = 0.0, roughness = 0.0;
    MaterialPoint points[MATERIAL_POINTS];
    for (uint32_t t = 0; t < m.triangle_count(); ++t) {
        const double a = triangle_material_points(scene, m, material, t, points, false);
        if (a <= 0.0) continue;
        double tm = 0.0, tr = 0.0; // per triangle first: the same sums as before the fits (bit for bit)
        for (const MaterialPoint& p : points) {
            tm += a / MATERIAL_POINTS * double(p.metallic);
            tr += a / MATERIAL_POINTS * double(p.roughness);
        }
        area += a;
        metallic += tm;
        roughness += tr;
    }
    if (area > 0.0) {
        s.metallic = std::clamp(float(double(s.metallic) * metallic / area), 0.0f, 1.0f);
        s.roughness = std::clamp(float(double(s.roughness) * roughness / area), 0.0f, 1.0f);
    }
    return s;
}

ModelAsset describe_asset(const Scene& scene, uint32_t mesh) {
    NBVH_CHECK(mesh < scene.meshes.size());
    const Mesh& m = scene.meshes[mesh];
    ModelAsset a;
    a.name = m.name;
    a.mesh = m.split_from.empty() ? m.name : m.split_from;
    const uint32_t mat = m.triangle_material.empty() ? 0u : m.triangle_material[0];
    a.material = material_label(scene, mat);
    for (const Instance& i : scene.instances)
        if (i.neural && i.mesh == mesh) a.node_paths.push_back(i.name);
    a.geometry_hash = geometry_fingerprint(m);
    a.material_hash = material_fingerprint(scene, mat);
    a.triangles = m.triangle_count();
    return a;
}

std::vector<int32_t> bind_model_to_scene(Scene& scene, const NeuralModel& model, const std::string& model_name) {
    // 1. The model decides which instances are neural: every instance of a glTF mesh it has an asset for.
    std::map<std::string, bool> wanted; // glTF mesh name -> found in the scene
    for (const ModelAsset& a : model.assets) wanted.emplace(a.mesh, false);
    for (Instance& i : scene.instances) {
        auto it = i.mesh < scene.meshes.size() ? wanted.find(scene.meshes[i.mesh].name) : wanted.end();
        i.neural = it != wanted.end();
        if (i.neural) it->second = true;
    }
    for (const ModelAsset& a : model.assets)
        if (!wanted[a.mesh])
            throw Error(strfmt("%s does not match the scene: asset '%s' (glTF mesh '%s') has no instance in it",
                               model_name.c_str(), a.name.c_str(), a.mesh.c_str()));
    // 2. Same cut as at training time, then every neural mesh must be an asset of the model.
    const bool legacy = model.assets.size() == 1 && model.assets[0].material.empty(); // version 1
    if (!legacy) split_neural_meshes(scene);
    std::map<std::string, int32_t> by_name;
    for (size_t i = 0; i < model.assets.size(); ++i) by_name.emplace(model.assets[i].name, int32_t(i));
    std::vector<int32_t> asset_of(scene.meshes.size(), -1);
    for (const Instance& inst : scene.instances) {
        if (!inst.neural || asset_of[inst.mesh] >= 0) continue;
        const Mesh& mesh = scene.meshes[inst.mesh];
        auto it = by_name.find(mesh.name);
        // A version-1 model has one asset named after its mesh, without material.
        if (it == by_name.end() && legacy) it = by_name.begin();
        if (it == by_name.end())
            throw Error(strfmt("%s does not match the scene: mesh '%s' (node '%s') has no asset in the model "
                               "(materials changed since training? retrain with nbvh train)",
                               model_name.c_str(), mesh.name.c_str(), inst.name.c_str()));
        const ModelAsset& a = model.assets[size_t(it->second)];
        const uint32_t mat = mesh.triangle_material.empty() ? 0u : mesh.triangle_material[0];
        if (a.geometry_hash != 0 && a.geometry_hash != geometry_fingerprint(mesh))
            throw Error(
                strfmt("%s does not match the scene: asset '%s' has different geometry (the mesh changed "
                       "since training, or --subdivide differs; retrain with nbvh train)",
                       model_name.c_str(), a.name.c_str()));
        if (a.material_hash != 0 && a.material_hash != material_fingerprint(scene, mat))
            throw Error(strfmt("%s does not match the scene: asset '%s' has a different base colour (the material "
                               "changed since training; retrain with nbvh train)",
                               model_name.c_str(), a.name.c_str()));
        asset_of[inst.mesh] = it->second;
    }
    return asset_of;
}

} // namespace nbvh
