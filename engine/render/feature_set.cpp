#include "engine/render/feature_set.h"

#include "engine/core/log.h"
#include "shaders/shared/scene_gpu.h"

namespace nbvh::render {

namespace {

bool texture_exists(const Scene& scene, const TextureRef& ref) {
    return ref.texture >= 0 && size_t(ref.texture) < scene.textures.size() &&
           scene.textures[size_t(ref.texture)].width > 0 && scene.textures[size_t(ref.texture)].height > 0;
}

} // namespace

SceneFeatures derive_features(const Scene& scene, const Environment& environment) {
    SceneFeatures f;
    // Only materials that some instanced triangle uses matter.
    std::vector<bool> used(scene.materials.size(), false);
    std::vector<bool> mesh_used(scene.meshes.size(), false);
    for (const Instance& inst : scene.instances)
        if (inst.mesh < scene.meshes.size()) mesh_used[inst.mesh] = true;
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        if (!mesh_used[m]) continue;
        for (uint32_t mat : scene.meshes[m].triangle_material)
            if (mat < used.size()) used[mat] = true;
    }
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        if (!used[i]) continue;
        const Material& m = scene.materials[i];
        const bool base_tex = texture_exists(scene, m.base_color_tex);
        if (base_tex || texture_exists(scene, m.metallic_roughness_tex) || texture_exists(scene, m.normal_tex) ||
            texture_exists(scene, m.emissive_tex))
            f.textures = true;
        if (texture_exists(scene, m.normal_tex)) f.normal_maps = true;
        if (m.emissive.x > 0.0f || m.emissive.y > 0.0f || m.emissive.z > 0.0f) f.emission = true;
        if (m.alpha_mode != AlphaMode::opaque) f.alpha_mask = true;
        if (m.transmission > 0.0f && m.metallic < 1.0f) f.transmission = true;
    }
    for (const Instance& inst : scene.instances) f.neural = f.neural || inst.neural;
    f.neural = false; // the neural passes arrive with the neural issue; neural instances render as triangles
    f.environment = !environment.empty() && environment.intensity > 0.0f;
    return f;
}

std::vector<vk::SpecConstant> specialization(const SceneFeatures& f) {
    return {{NB_SC_TEXTURES, f.textures ? 1u : 0u},       {NB_SC_NORMAL_MAPS, f.normal_maps ? 1u : 0u},
            {NB_SC_EMISSION, f.emission ? 1u : 0u},       {NB_SC_ENVIRONMENT, f.environment ? 1u : 0u},
            {NB_SC_ALPHA_MASK, f.alpha_mask ? 1u : 0u},   {NB_SC_TRANSMISSION, f.transmission ? 1u : 0u},
            {NB_SC_NEURAL, f.neural ? 1u : 0u}};
}

std::vector<std::string> pass_list(const SceneFeatures& f) {
    std::vector<std::string> passes = {"passes/camera_rays.comp", "passes/queue_args.comp", "passes/traverse.comp",
                                       "passes/shade.comp"};
    if (f.has_lights()) {
        passes.push_back("passes/queue_args.comp");
        passes.push_back("passes/shadow.comp");
    }
    passes.push_back("passes/accumulate.comp");
    passes.push_back("passes/resolve.comp");
    return passes;
}

std::string explain(const SceneFeatures& f, uint32_t max_depth) {
    auto yn = [](bool b) { return b ? "yes" : "no"; };
    std::string s;
    s += "scene features:\n";
    s += strfmt("  textures        %s%s\n", yn(f.textures), f.textures ? "" : "  (no texture fetches)");
    s += strfmt("  normal maps     %s\n", yn(f.normal_maps));
    s += strfmt("  emission        %s%s\n", yn(f.emission), f.emission ? "  (emissive-triangle NEE + MIS)" : "");
    s += strfmt("  environment     %s%s\n", yn(f.environment),
                f.environment ? "  (importance-sampled environment NEE + MIS)" : "");
    s += strfmt("  alpha masks     %s%s\n", yn(f.alpha_mask), f.alpha_mask ? "  (alpha test in traversal)" : "");
    s += strfmt("  transmission    %s\n", yn(f.transmission));
    s += strfmt("  neural assets   %s\n", yn(f.neural));
    s += strfmt("passes per sample wave (max depth %u):\n", max_depth);
    s += "  passes/camera_rays.comp      one ray per pixel -> ray queue\n";
    s += strfmt("  repeat %u x:\n", max_depth);
    s += "    passes/queue_args.comp     ray counter -> indirect dispatch arguments\n";
    s += "    passes/traverse.comp       TLAS/BLAS closest hit (indirect)\n";
    s += "    passes/shade.comp          BSDF, emission, light sampling, next ray (indirect)\n";
    if (f.has_lights()) {
        s += "    passes/queue_args.comp     shadow counter -> indirect dispatch arguments\n";
        s += "    passes/shadow.comp         any-hit visibility of light samples (indirect)\n";
    } else {
        s += "    (no shadow pass: nothing to sample by next-event estimation)\n";
    }
    s += "  passes/accumulate.comp       sample radiance -> film (non-finite samples dropped and counted)\n";
    s += "once per render:\n";
    s += "  passes/resolve.comp          film -> mean radiance\n";
    return s;
}

} // namespace nbvh::render
