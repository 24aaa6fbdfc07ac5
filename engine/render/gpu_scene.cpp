#include "engine/render/gpu_scene.h"

#include <algorithm>
#include <cmath>

#include "engine/core/error.h"
#include "engine/core/log.h"
#include "engine/render/gpu_memory.h"
#include "engine/render/texture_path.h"
#include "engine/scene/outline_shells.h"
#include "shaders/shared/sampling.h"

namespace nbvh::render {

namespace {

void rows_of(const glm::mat4& m, vec4 out[3]) {
    for (int r = 0; r < 3; ++r) out[r] = vec4(m[0][r], m[1][r], m[2][r], m[3][r]);
}

GpuTexRef tex_ref(const TextureRef& ref, size_t texture_count) {
    GpuTexRef g{};
    g.texture = (ref.texture >= 0 && size_t(ref.texture) < texture_count) ? ref.texture : -1;
    g.uv_set = ref.uv_set == 1 ? 1u : 0u;
    const glm::mat3& m = ref.transform; // column-major: uv' = m * (u, v, 1)
    g.row0 = vec3(m[0][0], m[1][0], m[2][0]);
    g.row1 = vec3(m[0][1], m[1][1], m[2][1]);
    return g;
}

float finite_or(float v, float fallback) { return std::isfinite(v) ? v : fallback; }

GpuMaterial pack_material(const Material& m, size_t texture_count) {
    GpuMaterial g{};
    g.base_color = vec4(finite_or(m.base_color.x, 1.0f), finite_or(m.base_color.y, 1.0f),
                        finite_or(m.base_color.z, 1.0f), finite_or(m.base_color.w, 1.0f));
    g.emissive = vec3(std::max(finite_or(m.emissive.x, 0.0f), 0.0f), std::max(finite_or(m.emissive.y, 0.0f), 0.0f),
                      std::max(finite_or(m.emissive.z, 0.0f), 0.0f));
    g.metallic = finite_or(m.metallic, 1.0f);
    g.roughness = finite_or(m.roughness, 1.0f);
    g.normal_scale = finite_or(m.normal_scale, 1.0f);
    g.alpha_cutoff = finite_or(m.alpha_cutoff, 0.5f);
    g.transmission = finite_or(m.transmission, 0.0f);
    g.alpha_mode = uint32_t(m.alpha_mode);
    g.double_sided = m.double_sided ? 1u : 0u;
    g.base_color_tex = tex_ref(m.base_color_tex, texture_count);
    g.metallic_roughness_tex = tex_ref(m.metallic_roughness_tex, texture_count);
    g.normal_tex = tex_ref(m.normal_tex, texture_count);
    g.emissive_tex = tex_ref(m.emissive_tex, texture_count);
    return g;
}

// Box-filter halving of an RGBA8 texture (odd sizes drop the last row/column).
Texture halve(const Texture& t) {
    Texture h;
    h.name = t.name;
    h.width = std::max(1u, t.width / 2);
    h.height = std::max(1u, t.height / 2);
    h.rgba8.resize(size_t(h.width) * h.height * 4);
    for (uint32_t y = 0; y < h.height; ++y)
        for (uint32_t x = 0; x < h.width; ++x)
            for (int c = 0; c < 4; ++c) {
                uint32_t sum = 0;
                for (uint32_t dy = 0; dy < 2; ++dy)
                    for (uint32_t dx = 0; dx < 2; ++dx) {
                        const uint32_t sx = std::min(t.width - 1, 2 * x + dx), sy = std::min(t.height - 1, 2 * y + dy);
                        sum += t.rgba8[(size_t(sy) * t.width + sx) * 4 + c];
                    }
                h.rgba8[(size_t(y) * h.width + x) * 4 + c] = uint8_t((sum + 2) / 4);
            }
    return h;
}

void pack_textures(const Scene& scene, const PackOptions& options, GpuSceneData& out) {
    out.texture_infos.assign(std::max<size_t>(scene.textures.size(), 1), GpuTextureInfo{0, 1, 1, 0});
    if (!options.textures || scene.textures.empty()) {
        out.texels.assign(1, 0xFFFFFFFFu);
        return;
    }
    // Halve the largest textures until everything fits one storage binding (texture_path.h).
    const TexelBufferPlan plan = plan_texel_buffer(scene.textures, options.texel_budget_bytes);
    out.texture_downscales = plan.total_halvings;
    if (out.texture_downscales > 0)
        log_info("render: %u texture halvings to fit %llu MiB of texels", out.texture_downscales,
                 (unsigned long long)(options.texel_budget_bytes >> 20));
    out.texels.clear();
    out.texels.reserve(plan.bytes / 4);
    for (size_t i = 0; i < scene.textures.size(); ++i) {
        Texture t;
        if (texture_valid(scene.textures[i])) {
            t = scene.textures[i];
            for (uint32_t k = 0; k < plan.halvings[i]; ++k) t = halve(t);
        } else {
            t.width = t.height = 1;
            t.rgba8 = {255, 255, 255, 255};
        }
        out.texture_infos[i] = GpuTextureInfo{uint32_t(out.texels.size()), t.width, t.height, 0};
        for (size_t p = 0; p < size_t(t.width) * t.height; ++p) {
            const uint8_t* c = &t.rgba8[p * 4];
            out.texels.push_back(uint32_t(c[0]) | (uint32_t(c[1]) << 8) | (uint32_t(c[2]) << 16) |
                                 (uint32_t(c[3]) << 24));
        }
    }
}

// Power of a punctual light for its selection probability (pbrt-v4 Light::Phi): 4 pi I for a point light,
// 2 pi I (1 - (cos_inner + cos_outer) / 2) for a spot, pi r^2 E for a directional light over a disc of the
// scene's radius r. Luminance of colour x intensity.
double punctual_power(const PunctualLight& l, float scene_radius) {
    const double lum = double(nb_luminance(l.color * l.intensity));
    switch (l.type) {
    case LightType::point: return 4.0 * NB_PI * lum;
    case LightType::spot:
        return 2.0 * NB_PI * lum * (1.0 - 0.5 * (std::cos(double(l.inner_cone)) + std::cos(double(l.outer_cone))));
    case LightType::directional: return NB_PI * double(scene_radius) * double(scene_radius) * lum;
    }
    return 0.0;
}

// KHR_lights_punctual lights after the emissive triangles (GpuLight), their power cdf after the emissive cdf.
void pack_punctual_lights(const Scene& scene, GpuSceneData& out) {
    std::vector<double> powers;
    double total = 0.0;
    for (const PunctualLight& l : scene.lights) {
        const glm::vec3 e = l.color * l.intensity;
        const double power = punctual_power(l, 0.5f * out.scene_extent);
        if (!(power > 0.0) || !std::isfinite(power) || !std::isfinite(e.x + e.y + e.z)) continue;
        GpuLight g{};
        g.kind = l.type == LightType::point ? NB_LIGHT_POINT : l.type == LightType::spot ? NB_LIGHT_SPOT
                                                                                         : NB_LIGHT_DIRECTIONAL;
        g.p0 = l.position;
        g.p1 = glm::normalize(l.direction);
        g.p2 = e;
        g.area = l.type == LightType::directional ? 0.0f : std::max(l.range, 0.0f);
        g.spot_scale = 0.0f;
        g.spot_offset = 1.0f;
        if (l.type == LightType::spot) {
            // KHR_lights_punctual's recommended smooth cone falloff.
            const float cos_outer = std::cos(l.outer_cone), cos_inner = std::cos(l.inner_cone);
            g.spot_scale = 1.0f / std::max(1.0e-3f, cos_inner - cos_outer);
            g.spot_offset = -cos_outer * g.spot_scale;
        }
        out.lights.push_back(g);
        powers.push_back(power);
        total += power;
    }
    out.punctual_light_count = uint32_t(powers.size());
    const size_t base = out.light_cdf.size();
    out.light_cdf.resize(base + powers.size() + 1, 0.0f);
    double acc = 0.0;
    for (size_t i = 0; i < powers.size(); ++i) {
        acc += powers[i];
        out.light_cdf[base + i + 1] = float(acc / total);
    }
    if (!powers.empty()) out.light_cdf.back() = 1.0f;
}

} // namespace

std::vector<bool> omitted_neural_meshes(const Scene& scene) {
    std::vector<bool> omit(scene.meshes.size(), false), seen(scene.meshes.size(), false);
    for (const Instance& i : scene.instances)
        if (i.mesh < scene.meshes.size()) {
            omit[i.mesh] = seen[i.mesh] ? omit[i.mesh] && i.neural : i.neural;
            seen[i.mesh] = true;
        }
    for (size_t m = 0; m < scene.meshes.size(); ++m)
        for (uint32_t mat : scene.meshes[m].triangle_material) {
            const uint32_t packed = mat < scene.materials.size() ? mat : 0u; // as pack_scene packs it
            if (omit[m] && packed < scene.materials.size() &&
                nb_luminance(scene.materials[packed].emissive) > 0.0f)
                omit[m] = false;
        }
    return omit;
}

GpuSceneData pack_scene(const Scene& scene, const SceneAccel& accel, const Environment& environment,
                        const PackOptions& options) {
    GpuSceneData out;
    const Aabb wb = scene.world_bounds();
    out.scene_extent = wb.empty() ? 1.0f : std::max(glm::length(wb.extent()), 1.0e-6f);

    // Vertices and per-mesh triangles in BLAS leaf order; BLAS nodes concatenated.
    std::vector<uint32_t> mesh_vertex_base(scene.meshes.size()), mesh_triangle_base(scene.meshes.size()),
        mesh_blas_root(scene.meshes.size());
    uint32_t empty_blas = BVH_INVALID; // the node omitted meshes point at (added on first use)
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const Mesh& mesh = scene.meshes[m];
        const MeshBvh& blas = accel.meshes[m];
        if (m < options.omit_mesh.size() && options.omit_mesh[m]) {
            if (empty_blas == BVH_INVALID) {
                empty_blas = uint32_t(out.blas_nodes.size());
                out.blas_nodes.push_back(to_wide_layout(Bvh{})[0]);
            }
            mesh_vertex_base[m] = mesh_triangle_base[m] = 0;
            mesh_blas_root[m] = empty_blas;
            ++out.omitted_meshes;
            out.omitted_unbuilt += blas.bounds_only ? 1u : 0u;
            out.omitted_bytes += mesh_gpu_bytes(mesh, blas);
            continue;
        }
        if (blas.bounds_only)
            throw Error(strfmt(
                "mesh %zu has no BLAS (built for its bounds only) but is not left out of the upload", m));
        mesh_vertex_base[m] = uint32_t(out.vertices.size());
        for (size_t v = 0; v < mesh.positions.size(); ++v) {
            GpuVertex g{};
            g.position = mesh.positions[v];
            g.normal = v < mesh.normals.size() ? mesh.normals[v] : glm::vec3(0.0f, 0.0f, 1.0f);
            const glm::vec2 uv0 = v < mesh.uv0.size() ? mesh.uv0[v] : glm::vec2(0.0f);
            g.u0 = uv0.x;
            g.v0 = uv0.y;
            g.tangent = v < mesh.tangents.size() ? mesh.tangents[v] : glm::vec4(0.0f);
            g.uv1 = v < mesh.uv1.size() ? mesh.uv1[v] : glm::vec2(0.0f);
            out.vertices.push_back(g);
        }
        mesh_triangle_base[m] = uint32_t(out.triangles.size());
        for (uint32_t original : blas.bvh.prim_indices) {
            const uint32_t base = mesh_vertex_base[m];
            uint32_t mat = original < mesh.triangle_material.size() ? mesh.triangle_material[original] : 0u;
            if (mat >= scene.materials.size()) mat = 0;
            out.triangles.push_back(GpuTriangle{base + mesh.indices[3 * original], base + mesh.indices[3 * original + 1],
                                                base + mesh.indices[3 * original + 2], mat});
            out.triangle_to_mesh_triangle.push_back(original);
        }
        // 4-wide quantized BLAS (to_wide_layout: an empty mesh gets a node without children).
        mesh_blas_root[m] = uint32_t(out.blas_nodes.size());
        const uint32_t offset = mesh_blas_root[m];
        for (GpuWideNode n : to_wide_layout(blas.bvh)) {
            for (uint32_t* ref : {&n.child0, &n.child1, &n.child2, &n.child3})
                if (!nb_is_leaf(*ref) && *ref != NB_CHILD_NONE) *ref += offset;
            out.blas_nodes.push_back(n);
        }
    }
    if (out.vertices.empty()) out.vertices.push_back(GpuVertex{});
    if (out.triangles.empty()) out.triangles.push_back(GpuTriangle{0, 0, 0, 0});
    if (out.blas_nodes.empty()) out.blas_nodes.push_back(to_wide_layout(Bvh{})[0]);

    // Instances in TLAS leaf order; inverted-hull outlines are seen by camera rays only (outline_shells.h).
    const std::vector<bool> shells = find_outline_shells(scene);
    out.tlas_nodes = to_gpu_layout(accel.tlas);
    for (uint32_t scene_instance : accel.tlas.prim_indices) {
        const uint32_t mesh = accel.instance_mesh[scene_instance];
        GpuInstance g{};
        rows_of(accel.object_to_world[scene_instance], g.object_to_world);
        rows_of(accel.world_to_object[scene_instance], g.world_to_object);
        g.blas_root = mesh_blas_root[mesh];
        g.first_triangle = mesh_triangle_base[mesh];
        g.kind = shells[scene_instance] ? NB_INSTANCE_CAMERA_ONLY : NB_INSTANCE_TRIANGLES;
        out.outline_shells += shells[scene_instance];
        g.mesh = mesh;
        out.instances.push_back(g);
        out.instance_to_scene.push_back(scene_instance);
    }
    const bool no_instances = out.instances.empty();
    if (out.tlas_nodes.empty()) {
        GpuBvhNode empty{};
        empty.left = empty.right = NB_CHILD_NONE;
        empty.lmin = empty.rmin = vec3(NB_INF);
        empty.lmax = empty.rmax = vec3(-NB_INF);
        out.tlas_nodes.push_back(empty);
    }
    if (no_instances) out.instances.push_back(GpuInstance{});
    if (out.outline_shells > 0)
        log_info("render: %u inverted-hull outline shell%s (inward-facing, single-sided, around other geometry): seen "
                 "by camera rays only", out.outline_shells, out.outline_shells == 1 ? "" : "s");

    // Materials and textures.
    for (const Material& m : scene.materials) out.materials.push_back(pack_material(m, scene.textures.size()));
    if (out.materials.empty()) out.materials.push_back(pack_material(Material{}, 0));
    pack_textures(scene, options, out);

    // Emissive triangles: power = luminance(emissive factor) * world area (see GpuLight).
    double total = 0.0;
    std::vector<double> powers;
    if (!no_instances) {
        for (uint32_t gi = 0; gi < out.instances.size(); ++gi) {
            const uint32_t si = out.instance_to_scene[gi];
            if (out.instances[gi].kind == NB_INSTANCE_CAMERA_ONLY) continue; // lights nothing it could shadow
            const uint32_t mesh = accel.instance_mesh[si];
            if (mesh < options.omit_mesh.size() && options.omit_mesh[mesh])
                continue; // emits nothing (omitted_neural_meshes)
            const glm::mat4& o2w = accel.object_to_world[si];
            const uint32_t first = mesh_triangle_base[mesh];
            const uint32_t count = accel.meshes[mesh].triangle_count();
            for (uint32_t k = 0; k < count; ++k) {
                const GpuTriangle& tri = out.triangles[first + k];
                const float lum = nb_luminance(out.materials[tri.material].emissive);
                if (!(lum > 0.0f)) continue;
                const glm::vec3 p0 = glm::vec3(o2w * glm::vec4(out.vertices[tri.v0].position, 1.0f));
                const glm::vec3 p1 = glm::vec3(o2w * glm::vec4(out.vertices[tri.v1].position, 1.0f));
                const glm::vec3 p2 = glm::vec3(o2w * glm::vec4(out.vertices[tri.v2].position, 1.0f));
                const float area = 0.5f * glm::length(glm::cross(p1 - p0, p2 - p0));
                if (!(area > 0.0f) || !std::isfinite(area)) continue;
                // Single-sided: the front face (counter-clockwise in object space) is the emitting one;
                // a mirroring instance (det < 0) turns the world-space cross product around.
                const float side = out.materials[tri.material].double_sided ? 0.0f
                                   : glm::determinant(glm::mat3(o2w)) < 0.0f ? -1.0f : 1.0f;
                out.lights.push_back(GpuLight{p0, gi, p1, first + k, p2, area, NB_LIGHT_TRIANGLE, side, 0.0f, 1.0f});
                powers.push_back(double(lum) * area);
                total += powers.back();
            }
        }
    }
    out.light_total_power = float(total);
    out.light_cdf.assign(powers.size() + 1, 0.0f);
    double acc = 0.0;
    for (size_t i = 0; i < powers.size(); ++i) {
        acc += powers[i];
        out.light_cdf[i + 1] = float(acc / total);
    }
    if (!powers.empty()) out.light_cdf.back() = 1.0f;
    out.emissive_light_count = total > 0.0 ? uint32_t(out.lights.size()) : 0u;
    pack_punctual_lights(scene, out);
    if (out.lights.empty()) out.lights.push_back(GpuLight{});

    out.environment = build_environment_table(environment, options.environment_budget_bytes);
    if (out.environment.halvings > 0)
        log_info("render: environment map %ux%u halved %u time%s to %ux%u to fit one storage binding (%llu MiB)",
                 environment.width, environment.height, out.environment.halvings,
                 out.environment.halvings == 1 ? "" : "s", out.environment.width, out.environment.height,
                 (unsigned long long)(options.environment_budget_bytes >> 20));
    return out;
}

} // namespace nbvh::render
