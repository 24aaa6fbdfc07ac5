#include "engine/render/feature_set.h"

#include <algorithm>
#include <cmath>

#include "engine/core/error.h"
#include "engine/core/log.h"
#include "shaders/shared/scene_gpu.h"

namespace nbvh::render {

namespace {

bool texture_exists(const Scene& scene, const TextureRef& ref) {
    return ref.texture >= 0 && size_t(ref.texture) < scene.textures.size() &&
           scene.textures[size_t(ref.texture)].width > 0 && scene.textures[size_t(ref.texture)].height > 0;
}

// Whether a transmissive material can have metallic < 1 somewhere: its factor, or a metallic-roughness
// texture (metallic = factor x B) with a texel below 255. Chess's glass pawn tops have metallicFactor 1
// (the glTF default) and metallic from the texture: the factor alone dropped their transmission.
bool metallic_below_one(const Scene& scene, const Material& m) {
    if (m.metallic < 1.0f) return true;
    if (!texture_exists(scene, m.metallic_roughness_tex)) return false;
    const std::vector<uint8_t>& px = scene.textures[size_t(m.metallic_roughness_tex.texture)].rgba8;
    for (size_t i = 2; i < px.size(); i += 4)
        if (px[i] < 255) return true;
    return false;
}

// `shadow`: the shadow rays' rounds (their leaf budget's count); else the path rays' (the camera rays'
// count, the secondary one after the first hit).
std::string neural_rounds_text(const NeuralPlan& n, const char* traverse, const char* what, bool shadow) {
    std::string s;
    s += "    passes/ray_sort.comp       rays in (direction levels, origin cell) order (--sort-rays; not camera rays)\n";
    s += strfmt("    %-26s op 0: %s, queues (ray, leaf) pairs (indirect)\n", traverse, what);
    if (n.batched_rounds > 0) {
        if (shadow)
            s += strfmt("    repeat %u x (batched rounds):\n", n.batched_rounds_shadow);
        else
            s += strfmt("    repeat %u x (batched rounds; %u after the first hit):\n", n.batched_rounds,
                        n.batched_rounds_secondary);
        s += "      passes/neural_args.comp    queued pairs -> indirect dispatch arguments\n";
        if (n.split_query) {
            s += "      passes/neural_gather.comp  hash grid of the queued pairs -> features (--neural-query)\n";
            s += "      passes/neural_query_mlp32.comp MLP of those features -> the pairs' hits\n";
            if (n.split_fused_rest)
                s +=
                    strfmt("      %-26s the rest: a round below --neural-split-min-pairs whole, or the pairs "
                           "past the features buffer\n",
                           n.query_shader.c_str());
        } else {
            s += strfmt("      %-26s hash grid + MLP of the queued pairs\n", n.query_shader.c_str());
        }
        s += strfmt("      %-26s op 1: resume the queried rays, queue their next leaves\n", traverse);
    }
    s += "    passes/neural_args.comp    rays still going -> indirect dispatch arguments\n";
    s += "    passes/neural_tail.comp    finishes them (scalar queries inline)\n";
    return s;
}

} // namespace

SceneFeatures derive_features(const Scene& scene, const Environment& environment, const NeuralRenderOptions& neural) {
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
        if (!m.double_sided) f.single_sided = true;
        if (m.transmission > 0.0f && metallic_below_one(scene, m)) f.transmission = true;
    }
    // Without a model (or with --classical) neural instances render from their triangles.
    if (neural.model && !neural.classical)
        for (const Instance& inst : scene.instances) f.neural = f.neural || inst.neural;
    f.environment = !environment.empty() && environment.intensity > 0.0f;
    for (const PunctualLight& l : scene.lights) {
        const glm::vec3 e = l.color * l.intensity;
        if (e.x + e.y + e.z > 0.0f && std::isfinite(e.x + e.y + e.z)) f.punctual = true;
    }
    return f;
}

SceneFeatures sampled_features(SceneFeatures f, const GpuSceneData& d) {
    f.emission = f.emission && d.emissive_light_count > 0;
    f.punctual = f.punctual && d.punctual_light_count > 0;
    f.environment = f.environment && d.environment.inv_mean > 0.0f && d.environment.intensity > 0.0f;
    return f;
}

const std::vector<ForcibleFeature>& forcible_features() {
    static const std::vector<ForcibleFeature> list = {
        {"textures", &SceneFeatures::textures},         {"normal_maps", &SceneFeatures::normal_maps},
        {"emission", &SceneFeatures::emission},         {"environment", &SceneFeatures::environment},
        {"alpha_mask", &SceneFeatures::alpha_mask},     {"transmission", &SceneFeatures::transmission},
        {"punctual", &SceneFeatures::punctual},         {"single_sided", &SceneFeatures::single_sided}};
    return list;
}

SceneFeatures all_forcible_features() {
    SceneFeatures f;
    for (const ForcibleFeature& x : forcible_features()) f.*x.flag = true;
    return f;
}

SceneFeatures with_forced(SceneFeatures derived, const SceneFeatures& forced) {
    if (forced.neural) throw Error("the neural feature cannot be forced: a hybrid render needs a model");
    for (const ForcibleFeature& x : forcible_features()) derived.*x.flag = derived.*x.flag || forced.*x.flag;
    return derived;
}

std::vector<vk::SpecConstant> specialization(const SceneFeatures& f) {
    return {{NB_SC_TEXTURES, f.textures ? 1u : 0u},       {NB_SC_NORMAL_MAPS, f.normal_maps ? 1u : 0u},
            {NB_SC_EMISSION, f.emission ? 1u : 0u},       {NB_SC_ENVIRONMENT, f.environment ? 1u : 0u},
            {NB_SC_ALPHA_MASK, f.alpha_mask ? 1u : 0u},   {NB_SC_TRANSMISSION, f.transmission ? 1u : 0u},
            {NB_SC_NEURAL, f.neural ? 1u : 0u},           {NB_SC_PUNCTUAL_LIGHTS, f.punctual ? 1u : 0u},
            {NB_SC_SINGLE_SIDED, f.single_sided ? 1u : 0u}};
}

std::optional<NeuralPlan> plan_neural(const vk::Context* ctx, const Scene& scene, const NeuralRenderOptions& o) {
    if (!o.model || o.classical) return std::nullopt;
    validate(o, scene); // throws what the renderer would
    NBVH_CHECK_MSG(ctx != nullptr, "plan_neural: a hybrid render needs the device to choose its kernel");
    // The renderer's own stage (ray capacity 1: only its choices are read, no ray buffers are installed).
    const NeuralStage stage(*ctx, *o.model, scene, o, 1);
    NeuralPlan p;
    p.kernel = stage.query_description();
    p.split_query = stage.split();
    p.split_fused_rest = stage.split_overflow();
    p.query_shader = stage.query_shader();
    p.lod_primary = stage.params().lod_primary;
    p.lod_secondary = stage.params().lod_secondary;
    p.lod_count = std::max(1u, o.model->lod_count);
    p.leaf_budget = stage.rounds();
    p.leaf_budget_secondary = stage.params().max_rounds_secondary;
    p.truncated_shadows_occlusion = stage.params().truncated_shadows_occlusion;
    p.leaves_per_round = stage.params().leaves_per_round;
    p.leaves_per_round_camera = stage.params().leaves_per_round_camera;
    p.batched_rounds = stage.batched_rounds(NeuralStage::RayClass::camera);
    p.batched_rounds_secondary = stage.batched_rounds(NeuralStage::RayClass::path);
    p.batched_rounds_shadow = stage.batched_rounds(NeuralStage::RayClass::shadow);
    p.leaf_budget_shadow = stage.params().max_rounds_shadow;
    p.occupancy = stage.params().occupancy != 0u;
    p.model_has_masks = !o.model->occupancy.empty();
    p.backface_escape = o.backface_escape;
    p.node_materials = stage.params().materials != 0u;
    p.material_fits = stage.params().material_fits != 0u;
    p.model_has_materials = !o.model->node_materials.empty();
    p.model_has_fits = !o.model->material_fits.empty();
    p.fits_requested = o.materials == NeuralMaterials::fit || o.materials == NeuralMaterials::mix;
    p.material_spread = stage.params().material_spread != 0u;
    for (const Instance& inst : scene.instances) p.instances += inst.neural;
    p.assets = uint32_t(o.model->assets.size());
    return p;
}

namespace {

// The neural rounds of one traversal (WavefrontRenderer::record_neural_rounds): op 0 over every ray, then
// per batched round (`rounds`) the query of the queued pairs and the resumed traversal, then neural_tail.
void neural_rounds(std::vector<std::string>& passes, const NeuralPlan& n, const char* traverse, uint32_t rounds) {
    passes.push_back("passes/ray_sort.comp"); // bounces > 0 and shadow rays (RenderOptions::sort_rays)
    passes.push_back(traverse);
    for (uint32_t r = 0; r < rounds; ++r) {
        passes.push_back("passes/neural_args.comp");
        passes.push_back(n.query_shader);
        passes.push_back(traverse);
    }
    passes.push_back("passes/neural_args.comp");
    passes.push_back("passes/neural_tail.comp");
}

} // namespace

std::vector<std::string> pass_list(const SceneFeatures& f, const NeuralPlan* neural) {
    const NeuralPlan* n = f.neural ? neural : nullptr;
    std::vector<std::string> passes = {"passes/camera_rays.comp", "passes/queue_args.comp"};
    if (n) {
        neural_rounds(passes, *n, "passes/neural_traverse.comp", n->batched_rounds);
    } else {
        passes.push_back("passes/ray_sort.comp"); // secondary rays (RenderOptions::sort_rays)
        passes.push_back("passes/traverse.comp");
    }
    passes.push_back("passes/shade.comp");
    if (f.has_lights()) {
        passes.push_back("passes/queue_args.comp");
        if (n) neural_rounds(passes, *n, "passes/neural_shadow.comp", n->batched_rounds_shadow);
        else passes.push_back("passes/ray_sort.comp");
        passes.push_back("passes/shadow.comp");
    }
    passes.push_back("passes/accumulate.comp");
    passes.push_back("passes/resolve.comp");
    return passes;
}

std::string explain(const SceneFeatures& f, uint32_t max_depth, const NeuralPlan* neural, const TexturePlan* textures) {
    const NeuralPlan* n = f.neural ? neural : nullptr;
    auto yn = [](bool b) { return b ? "yes" : "no"; };
    std::string s;
    s += "scene features:\n";
    s += strfmt("  textures        %s%s\n", yn(f.textures), f.textures ? "" : "  (no texture fetches)");
    if (f.textures && textures) s += "    path          " + describe(*textures) + "\n";
    s += strfmt("  normal maps     %s\n", yn(f.normal_maps));
    s += strfmt("  emission        %s%s\n", yn(f.emission), f.emission ? "  (emissive-triangle NEE + MIS)" : "");
    s += strfmt("  environment     %s%s\n", yn(f.environment),
                f.environment ? "  (importance-sampled environment NEE + MIS)" : "");
    s += strfmt("  punctual lights %s%s\n", yn(f.punctual), f.punctual ? "  (KHR_lights_punctual NEE, shadow rays)" : "");
    s += strfmt("  alpha masks     %s%s\n", yn(f.alpha_mask), f.alpha_mask ? "  (alpha test in traversal)" : "");
    s += strfmt("  transmission    %s\n", yn(f.transmission));
    s += strfmt("  single-sided    %s%s\n", yn(f.single_sided), f.single_sided ? "  (back faces culled in traversal)" : "");
    if (n) {
        s += strfmt("  neural assets   yes  (%u instance%s answered by the model's %u asset%s)\n", n->instances,
                    n->instances == 1 ? "" : "s", n->assets, n->assets == 1 ? "" : "s");
        s += "neural stage:\n";
        s += strfmt("  MLP path        %s\n", n->kernel.c_str());
        s += strfmt("  LoD             camera rays %u, after the first hit %u (the model has %u: 0 = finest)\n",
                    n->lod_primary, n->lod_secondary, n->lod_count);
        s += strfmt("  leaves per ray  at most %u (rays after the first hit %u, shadow rays %u), %u queued "
                    "per round (the others %u): %u batched round%s (the others %u, shadow rays %u), then "
                    "neural_tail\n",
                    n->leaf_budget, n->leaf_budget_secondary, n->leaf_budget_shadow, n->leaves_per_round_camera,
                    n->leaves_per_round, n->batched_rounds, n->batched_rounds == 1 ? "" : "s",
                    n->batched_rounds_secondary, n->batched_rounds_shadow);
        const float occl = n->truncated_shadows_occlusion;
        s += occl >= 1.0f ? std::string("  truncated rays  a shadow ray is occluded by the leaf its budget leaves "
                                        "out, a path ray keeps its closest hit\n")
             : occl <= 0.0f
                 ? std::string("  truncated rays  keep their closest hit, a shadow ray is unoccluded "
                               "(--neural-truncated-shadows pass)\n")
                 : strfmt("  truncated rays  a shadow ray is occluded by the leaf its budget leaves out with "
                          "probability %.3g, a path ray keeps its closest hit\n",
                          occl);
        s += strfmt("  occupancy masks %s\n", n->occupancy          ? "on  (leaves crossing only empty cells are not queried)"
                                              : n->model_has_masks ? "off (--neural-occupancy off)"
                                                                   : "off (the model has no masks: format version < 3 or built without its triangles)");
        s += strfmt("  materials       %s\n", n->material_spread      ? "per node, fit + spread (metallic/roughness of the N-BVH node that answered the hit, linear in its predicted albedo, +- what the fit leaves)"
                                              : n->material_fits        ? "per node, fit (--neural-materials fit: metallic/roughness of the N-BVH node that answered the hit, linear in its predicted albedo)"
                                              : n->node_materials     ? (n->fits_requested ? "per node, mean (the model has no fits: format version < 5)"
                                                                                           : "per node, mean (--neural-materials node)")
                                              : n->model_has_materials ? "per asset (--neural-materials asset)"
                                                                       : "per asset (the model has no node materials: format version < 4 or built without its triangles)");
        s += strfmt("  back-face escape %s\n", n->backface_escape ? "on  (rays leaving a hit seen from behind skip back faces)"
                                                                 : "off (--neural-backface-escape off)");
    } else {
        s += strfmt("  neural assets   %s\n", yn(f.neural));
    }
    s += strfmt("passes per sample wave (max depth %u):\n", max_depth);
    s += "  passes/camera_rays.comp      one ray per pixel -> ray queue\n";
    s += strfmt("  repeat %u x:\n", max_depth);
    s += "    passes/queue_args.comp     ray counter -> indirect dispatch arguments\n";
    if (n) {
        s += neural_rounds_text(*n, "passes/neural_traverse.comp", "closest hit through triangles and N-BVHs",
                                false);
    } else {
        s += "    passes/ray_sort.comp       bounces > 0: rays in (direction levels, origin cell) order (--sort-rays)\n";
        s += "    passes/traverse.comp       TLAS/BLAS closest hit (indirect)\n";
    }
    s += "    passes/shade.comp          BSDF, emission, light sampling, next ray (indirect)\n";
    if (f.has_lights()) {
        s += "    passes/queue_args.comp     shadow counter -> indirect dispatch arguments\n";
        if (n)
            s += neural_rounds_text(*n, "passes/neural_shadow.comp", "visibility through N-BVHs", true);
        else s += "    passes/ray_sort.comp       shadow rays in (direction levels, origin cell) order (--sort-rays)\n";
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
